// End-to-end latency of the planner daemon's node ("the daemon answers an obstacle change in
// X ms"): an in-process PlannerNode on a memq:// LCM, a client that publishes goal_t and
// obstacle_list_t and waits for the plan_t answering it. For each of N seeded problems on the
// iiwa desk scene (robots/scenes/iiwa_desk.yaml) a fresh node receives, in order:
//   1. a first goal (sampled as bench/replanning: payload above the desk),
//   2. an obstacle move: a ball (r = 5 cm) added far from the arm, then moved onto the first
//      plan's path (touching the block at mid-course), timed on the move,
//      and removed again (replace_all with an empty list),
//   3. a nearby goal (every joint moved within ±radius of the first goal), a medium and a large
//      one (within ±2.5·radius and ±5·radius of the first goal), and a far goal (an independent
//      sampled goal). Each goal change is measured from the previous goal (JSON samples).
// Both the incremental node (PlannerNodeOptions::incremental, the default) and the batch node
// (incremental = false) run the same sequence. Latency = publish to receipt of the plan_t,
// medians over the runs that validated. Prints one JSON document, then a Markdown table.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <fstream>
#include <iostream>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>
#include <thread>

#include "bench/common/bench_stats.h"
#include "bench/common/iiwa_goals.h"
#include "daemon/planner_node.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/goal_sampler.h"
#include "kinograph/planning/io/scene.h"
#include "lcmtypes/safe_decode.h"

namespace kinograph::bench {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

// The client side: publishes and waits for the next plan_t on the plan channel.
class Client {
 public:
  explicit Client(lcm::LCM& lcm) : lcm_(lcm) {
    sub_ = lcm.subscribe("IIWA_PLAN", &Client::on_plan, this);
  }
  ~Client() { lcm_.unsubscribe(sub_); }
  void on_plan(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    plan_t msg;
    if (!lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg).ok) return;
    std::lock_guard lock(mutex_);
    plans_.push_back(std::move(msg));
    received_.push_back(Clock::now());
    cv_.notify_all();
  }
  // Publishes `msg` on `channel` and waits for the next plan: (plan, seconds since publishing).
  template <class Msg>
  std::optional<std::pair<plan_t, double>> request(const std::string& channel, const Msg& msg) {
    size_t before;
    {
      std::lock_guard lock(mutex_);
      before = plans_.size();
    }
    const auto t0 = Clock::now();
    lcm_.publish(channel, &msg);
    std::unique_lock lock(mutex_);
    if (!cv_.wait_for(lock, std::chrono::seconds(120), [&] { return plans_.size() > before; })) {
      return std::nullopt;
    }
    return std::pair{plans_[before], std::chrono::duration<double>(received_[before] - t0).count()};
  }

 private:
  lcm::LCM& lcm_;
  lcm::Subscription* sub_ = nullptr;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<plan_t> plans_;
  std::vector<Clock::time_point> received_;
};

goal_t joint_goal(int64_t id, const Eigen::VectorXd& q) {
  goal_t g{};
  g.goal_id = id;
  g.kind = goal_t::KIND_JOINT_CONFIGURATION;
  g.num_joints = static_cast<int32_t>(q.size());
  g.joint_position.assign(q.data(), q.data() + q.size());
  g.ee_quaternion[0] = 1;
  return g;
}

obstacle_list_t ball_at(const Eigen::Vector3d& p) {
  obstacle_list_t list{};
  obstacle_t o{};
  o.id = "ball";
  o.action = obstacle_t::ADD_OR_MOVE;
  o.shape = obstacle_t::SPHERE;
  o.size[0] = 0.05;
  for (int i = 0; i < 3; ++i) o.position[i] = p[i];
  o.quaternion[0] = 1;
  list.obstacles.push_back(o);
  list.num_obstacles = 1;
  return list;
}

// One row of the table: one kind of request answered by one node mode.
struct Row {
  std::vector<double> latency_ok, solve_ok;
  std::map<std::string, int> methods;
  int runs = 0, ok = 0;
  json samples = json::array();  // every request: goal change, method, status, latency
  void add(const plan_t& p, double latency, double goal_change) {
    ++runs;
    ++methods[p.method];
    samples.push_back({{"goal_change_rad", goal_change},
                       {"method", p.method},
                       {"success", p.status == plan_t::SUCCESS},
                       {"latency_s", latency}});
    if (p.status == plan_t::SUCCESS) {
      ++ok;
      latency_ok.push_back(latency);
      solve_ok.push_back(p.solve_time_s);
    }
  }
  json to_json() const {
    return {{"runs", runs},
            {"successes", ok},
            {"latency_s_median", median(latency_ok)},
            {"latency_s_max", max_of(latency_ok)},
            {"solve_s_median", median(solve_ok)},
            {"methods", methods},
            {"samples", samples}};
  }
};

}  // namespace
}  // namespace kinograph::bench

int main(int argc, char** argv) {
  using namespace kinograph;
  using namespace kinograph::bench;
  CLI::App app{"daemon_bench: end-to-end replanning latency of kinographd's node over memq://"};
  int runs = 20;
  double radius = 0.2;
  std::string json_path, level = "warn";
  app.add_option("--runs", runs, "problems (first goals) per mode");
  app.add_option("--radius", radius, "nearby goal: largest joint change (rad)");
  app.add_option("--json", json_path, "also write the JSON here");
  bool samples = false;
  int only = -1;
  app.add_option("--only", only, "run only this problem (index from 0; to look at one case)");
  app.add_flag("--samples", samples, "list every request in the JSON (goal change, outcome)");
  app.add_option("--log-level", level, "the node's log level (info shows every plan)");
  double max_goal_change = std::numeric_limits<double>::infinity();
  app.add_option("--max-goal-change", max_goal_change,
                 "incremental node: goals farther than this (rad, largest joint change) are "
                 "planned from scratch (PlannerNodeOptions::max_incremental_goal_change)");
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::from_str(level));

  const std::string scene_path =
      std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml";
  const planning::Scene scene = planning::load_scene(scene_path);
  const planning::Problem& problem = scene.problem;
  planning::GoalSampler first_goals(problem, iiwa_goal_options(1));
  planning::GoalSampler far_goals(problem, iiwa_goal_options(7));
  planning::GoalSampler checker(problem, iiwa_goal_options(99));
  const int payload = problem.model->frame_index("payload");

  const std::vector<std::string> kinds = {"first goal",  "obstacle move", "obstacle remove",
                                          "nearby goal", "medium goal",   "large goal",
                                          "far goal"};
  const std::vector<std::string> modes = {"incremental", "batch"};
  std::map<std::string, std::map<std::string, Row>> rows;  // [mode][kind]
  std::vector<std::pair<Eigen::VectorXd, Eigen::VectorXd>> goals;
  for (int i = 0; i < runs; ++i) {
    auto a = first_goals.sample();
    auto b = far_goals.sample();
    if (!a || !b) break;
    goals.emplace_back(*a, *b);
  }
  for (int i = 0; i < static_cast<int>(goals.size()); ++i) {
    if (only >= 0 && i != only) continue;
    const auto& [a, b] = goals[i];
    const auto near = nearby_goal(checker, a, radius, 1000 + i);
    const auto medium = nearby_goal(checker, a, 2.5 * radius, 2000 + i);
    const auto large = nearby_goal(checker, a, 5 * radius, 3000 + i);
    for (const std::string& mode : modes) {
      lcm::LCM lcm("memq://");
      daemon::PlannerNodeOptions options;
      options.channel_prefix = "IIWA";
      options.status_period_s = 10;
      options.replanning.use_incremental = mode == "incremental";
      options.replanning.max_incremental_goal_change = max_goal_change;
      daemon::PlannerNode node(scene, options, &lcm);
      Client client(lcm);
      std::atomic<bool> stop{false};
      std::thread thread([&] { node.run(stop); });
      Eigen::VectorXd current_goal = a;
      auto record = [&](const std::string& kind, const auto& answer, const Eigen::VectorXd& goal) {
        if (!answer) {
          spdlog::error("run {} {} {}: no answer", i, mode, kind);
          return false;
        }
        const double change = (goal - current_goal).cwiseAbs().maxCoeff();
        current_goal = goal;
        rows[mode][kind].add(answer->first, answer->second, change);
        std::cerr << "run " << i << " " << mode << " " << kind << ": " << answer->first.method
                  << " status " << int(answer->first.status) << " " << answer->second * 1e3
                  << " ms, goal change " << change << " rad\n";
        return answer->first.status == plan_t::SUCCESS;
      };
      const auto first = client.request("IIWA_GOAL", joint_goal(1, a));
      if (record("first goal", first, a)) {
        // The ball: first out of reach, then moved to 12 cm above the block's centre at
        // mid-course (2 cm from the block, inside the safety distance ε = 5 cm: the current plan
        // violates its collision constraint there), then removed.
        const auto far_ball = client.request("IIWA_OBSTACLES", ball_at({-1.5, -1.5, 0.3}));
        const plan_t& p = first->first;
        const int mid = p.num_steps / 2;
        dynamics::Data data(*problem.model);
        dynamics::forward_kinematics(
            *problem.model, data, Eigen::Map<const Eigen::VectorXd>(p.q[mid].data(), p.num_joints));
        const Eigen::Vector3d block =
            dynamics::frame_pose(*problem.model, data, payload).translation();
        if (far_ball && far_ball->first.status == plan_t::SUCCESS) {
          record("obstacle move",
                 client.request("IIWA_OBSTACLES", ball_at(block + Eigen::Vector3d(0, 0, 0.12))), a);
          obstacle_list_t none{};
          none.replace_all = true;
          record("obstacle remove", client.request("IIWA_OBSTACLES", none), a);
        }
        if (near) record("nearby goal", client.request("IIWA_GOAL", joint_goal(2, *near)), *near);
        if (medium) {
          record("medium goal", client.request("IIWA_GOAL", joint_goal(3, *medium)), *medium);
        }
        if (large) {
          record("large goal", client.request("IIWA_GOAL", joint_goal(5, *large)), *large);
        }
        record("far goal", client.request("IIWA_GOAL", joint_goal(4, b)), b);
      }
      stop = true;
      thread.join();
    }
  }

  json j;
  j["scene"] = "robots/scenes/iiwa_desk.yaml";
  j["runs"] = goals.size();
  j["radius"] = radius;
  for (const auto& mode : modes) {
    for (const auto& kind : kinds) j["results"][mode][kind] = rows[mode][kind].to_json();
  }
  if (!samples) {
    for (auto& [mode, by_kind] : j["results"].items()) {
      for (auto& [kind, row] : by_kind.items()) row.erase("samples");
    }
  }
  std::cout << j.dump(2) << "\n\n";
  if (!json_path.empty()) std::ofstream(json_path) << j.dump(2) << "\n";
  std::cout << "| request | node | success | median latency (ms) | max (ms) | median solve (ms) | "
               "methods |\n|---|---|---|---|---|---|---|\n";
  for (const auto& kind : kinds) {
    for (const auto& mode : modes) {
      const Row& r = rows[mode][kind];
      std::string methods;
      for (const auto& [m, n] : r.methods)
        methods += (methods.empty() ? "" : ", ") + m + " " + std::to_string(n);
      char line[512];
      std::snprintf(line, sizeof line, "| %s | %s | %d/%d | %.0f | %.0f | %.0f | %s |\n",
                    kind.c_str(), mode.c_str(), r.ok, r.runs, median(r.latency_ok) * 1e3,
                    max_of(r.latency_ok) * 1e3, median(r.solve_ok) * 1e3, methods.c_str());
      std::cout << line;
    }
  }
  return 0;
}

// Self-collision and the floor on the iiwa desk: (1) seeded random starts (block below the
// desk top) to seeded random goals (above and beside it), with a horizon each move can make,
// checked afterwards by a brute-force clearance walk of our own; (2) the price of the checks on
// Table I's iiwa problems, every goal planned with and without them, interleaved. Prints one
// JSON document, then Markdown tables; see bench/self_collision/README.md.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench/common/bench_stats.h"
#include "bench/common/iiwa_goals.h"
#include "bench/common/timed_plan.h"
#include "kinograph/collision/collision_world.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/clearance_world.h"
#include "kinograph/planning/goal_sampler.h"
#include "kinograph/planning/io/scene.h"

namespace kinograph::bench {
namespace {

using nlohmann::json;
using planning::Plan;
using planning::Problem;

const std::string kScenes = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/";
// Points per interval of the clearance walk (the validator samples 10 and walks adaptively).
constexpr int kWalkSamples = 40;

struct Clearance {
  double self = std::numeric_limits<double>::infinity();
  double floor = std::numeric_limits<double>::infinity();
};

// Self and floor clearance of a plan on the cubic Hermite interpolant of its knots, every pair
// to the end (no culling), kWalkSamples points per interval: independent of the planner's
// factors and of the validator's adaptive walk.
Clearance walk(const Problem& problem, const Plan& plan) {
  const dynamics::Model& model = *problem.model;
  collision::CollisionWorldOptions self_only;
  self_only.self_collision = true;
  self_only.cull = false;
  self_only.self_collision_excluded = problem.self_and_floor.allowed_pairs;
  collision::CollisionWorld self(model, self_only);
  collision::CollisionWorldOptions floor_only;
  floor_only.cull = false;
  collision::CollisionWorld floor(model, floor_only);
  floor.add_obstacle(planning::floor_obstacle(problem.self_and_floor.floor.value_or(0.0)));
  dynamics::Data data(model);
  Clearance c;
  const double dt = problem.dt();
  for (int k = 0; k < problem.steps; ++k) {
    for (int i = 0; i <= kWalkSamples; ++i) {
      const double s = static_cast<double>(i) / kWalkSamples, s2 = s * s, s3 = s2 * s;
      const Eigen::VectorXd q =
          ((2 * s3 - 3 * s2 + 1) * plan.q.row(k) + (s3 - 2 * s2 + s) * dt * plan.qd.row(k) +
           (-2 * s3 + 3 * s2) * plan.q.row(k + 1) + (s3 - s2) * dt * plan.qd.row(k + 1))
              .transpose();
      dynamics::forward_kinematics(model, data, q);
      c.self = std::min(c.self, self.closest(data).distance);
      c.floor = std::min(c.floor, floor.closest(data).distance);
    }
  }
  return c;
}

// A horizon the move can make: twice the time the slowest joint needs at its velocity limit
// (a smooth rest-to-rest profile peaks at 1.5× its mean speed), at least the scene's 3 s;
// 10 steps per second.
void fit_horizon(Problem& p) {
  double t = 0;
  for (int j = 0; j < p.model->nq(); ++j) {
    t = std::max(t, std::abs(p.goal.q[j] - p.start_q[j]) / p.model->bodies[j].limits.velocity);
  }
  p.horizon = std::max(3.0, std::ceil(2 * t * 10) / 10);
  p.steps = static_cast<int>(std::lround(10 * p.horizon));
}

Problem without_self_and_floor(Problem p) {
  p.self_and_floor.self_collision = false;
  p.self_and_floor.floor.reset();
  return p;
}

json times(const std::vector<Run>& runs) {
  std::vector<double> all, ok;
  int successes = 0;
  for (const Run& r : runs) {
    all.push_back(r.wall_s);
    if (r.plan.success()) {
      ok.push_back(r.wall_s);
      ++successes;
    }
  }
  return {{"runs", runs.size()},         {"successes", successes},
          {"time_s_median", median(ok)}, {"time_s_mean", mean(ok)},
          {"time_s_max", max_of(ok)},    {"time_s_median_all", median(all)}};
}

// A JSON number, NaN for null (NaN is written as null).
double num(const json& j) { return j.is_number() ? j.get<double>() : std::nan(""); }

// Self and floor clearance of one configuration, as walk() measures them.
Clearance at(const Problem& problem, const Eigen::VectorXd& q) {
  Plan still;
  still.q = q.transpose().replicate(2, 1);
  still.qd = Eigen::MatrixXd::Zero(2, q.size());
  Problem one = problem;
  one.steps = 1;
  return walk(one, still);
}

int run(int argc, char** argv) {
  int count = 50;
  std::string json_path;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--count" && i + 1 < argc) {
      count = std::stoi(argv[++i]);
    } else if (a == "--json" && i + 1 < argc) {
      json_path = argv[++i];
    } else {
      std::cerr << "usage: self_collision_bench [--count N] [--json FILE]\n";
      return 1;
    }
  }
  spdlog::set_level(spdlog::level::warn);
  const planning::BatchPlanner planner;
  const planning::Scene desk = planning::load_scene(kScenes + "iiwa_desk.yaml");
  json result;

  // (1) Random starts to random goals.
  {
    planning::GoalSamplerOptions so = iiwa_goal_options(11);
    so.region =
        Eigen::AlignedBox3d(Eigen::Vector3d(0.3, -0.6, 0.15), Eigen::Vector3d(0.9, 0.6, 0.5));
    planning::GoalSampler starts(desk.problem, so);
    planning::GoalSampler goals(desk.problem, iiwa_goal_options(12));
    const std::vector<Eigen::VectorXd> qs = starts.sample(count), qg = goals.sample(count);
    json cases = json::array();
    int ok = 0, clear = 0, ok_without = 0;
    double worst_self = std::numeric_limits<double>::infinity(), worst_floor = worst_self;
    std::vector<double> ok_times, horizons;
    for (std::size_t i = 0; i < std::min(qs.size(), qg.size()); ++i) {
      Problem p = desk.problem;
      p.start_q = qs[i];
      p.goal.q = qg[i];
      fit_horizon(p);
      horizons.push_back(p.horizon);
      const Run r = plan_once(planner, p);
      const Run blind = plan_once(planner, without_self_and_floor(p));
      if (blind.plan.success()) ++ok_without;
      json c = {{"case", i},
                {"horizon_s", p.horizon},
                {"success", r.plan.success()},
                {"status", to_string(r.plan.stats.status)},
                {"time_s", r.wall_s},
                {"success_without", blind.plan.success()}};
      const Clearance cs = at(p, p.start_q), cg = at(p, p.goal.q);
      c["start_q"] = std::vector<double>(p.start_q.data(), p.start_q.data() + p.start_q.size());
      c["goal_q"] = std::vector<double>(p.goal.q.data(), p.goal.q.data() + p.goal.q.size());
      c["start_self_m"] = cs.self;
      c["start_floor_m"] = cs.floor;
      c["goal_self_m"] = cg.self;
      c["goal_floor_m"] = cg.floor;
      if (r.plan.success()) {
        ++ok;
        ok_times.push_back(r.wall_s);
        const Clearance cl = walk(p, r.plan);
        worst_self = std::min(worst_self, cl.self);
        worst_floor = std::min(worst_floor, cl.floor);
        if (cl.self >= 0 && cl.floor >= 0) ++clear;
        c["self_clearance_m"] = cl.self;
        c["floor_clearance_m"] = cl.floor;
      } else {
        c["reason"] = r.plan.stats.reason;
        c["first_failure"] =
            r.plan.validation.failures.empty() ? std::string() : r.plan.validation.failures[0];
      }
      std::cerr << "random " << i << ": " << c.dump() << "\n";
      cases.push_back(c);
    }
    result["random_desk"] = {{"cases", cases.size()},
                             {"successes", ok},
                             {"success_rate", cases.empty() ? 0.0 : double(ok) / cases.size()},
                             {"successes_clear", clear},
                             {"successes_without_self_and_floor", ok_without},
                             {"min_self_clearance_m", worst_self},
                             {"min_floor_clearance_m", worst_floor},
                             {"time_s_median", median(ok_times)},
                             {"horizon_s_median", median(horizons)},
                             {"horizon_s_max", max_of(horizons)},
                             {"start_candidates_drawn", starts.attempts()},
                             {"goal_candidates_drawn", goals.attempts()},
                             {"runs", cases}};
  }

  // (2) Table I's iiwa problems with and without self-collision and the floor, interleaved.
  for (const auto& [key, file, seed] : {std::tuple{"iiwa_task1", "iiwa_desk.yaml", 1},
                                        std::tuple{"iiwa_task2", "iiwa_min_torque.yaml", 2}}) {
    const planning::Scene scene = planning::load_scene(kScenes + file);
    planning::GoalSampler sampler(scene.problem, iiwa_goal_options(seed));
    std::vector<Run> with, without;
    for (const Eigen::VectorXd& q : sampler.sample(count)) {
      Problem p = scene.problem;
      p.goal.q = q;
      with.push_back(plan_once(planner, p));
      without.push_back(plan_once(planner, without_self_and_floor(p)));
    }
    int with_clear = 0, without_unclear = 0;
    json failed = json::array();
    for (std::size_t i = 0; i < with.size(); ++i) {
      if (with[i].plan.success()) {
        const Clearance c = walk(scene.problem, with[i].plan);
        if (c.self >= 0 && c.floor >= 0) ++with_clear;
      } else {
        const Clearance g = at(scene.problem, with[i].plan.q.bottomRows(1).transpose());
        const Eigen::VectorXd qg = with[i].plan.q.bottomRows(1).transpose();
        failed.push_back({{"goal", i},
                          {"goal_q", std::vector<double>(qg.data(), qg.data() + qg.size())},
                          {"status", to_string(with[i].plan.stats.status)},
                          {"reason", with[i].plan.stats.reason},
                          {"goal_self_m", g.self},
                          {"goal_floor_m", g.floor},
                          {"without_success", without[i].plan.success()}});
      }
      if (without[i].plan.success()) {
        const Clearance c = walk(scene.problem, without[i].plan);
        if (c.self < 0 || c.floor < 0) ++without_unclear;
      }
    }
    // The price per plan: over the goals both plan validly, the ratio of the two times.
    std::vector<double> ratio, both_with, both_without;
    for (std::size_t i = 0; i < with.size(); ++i) {
      if (!with[i].plan.success() || !without[i].plan.success()) continue;
      ratio.push_back(with[i].wall_s / without[i].wall_s);
      both_with.push_back(with[i].wall_s);
      both_without.push_back(without[i].wall_s);
    }
    result[key] = {{"both_valid", ratio.size()},
                   {"both_valid_time_ratio_median", median(ratio)},
                   {"both_valid_with_time_s_median", median(both_with)},
                   {"both_valid_without_time_s_median", median(both_without)},
                   {"with", times(with)},
                   {"without", times(without)},
                   {"with_successes_clear", with_clear},
                   {"without_successes_self_or_floor_colliding", without_unclear},
                   {"goal_candidates_drawn", sampler.attempts()},
                   {"with_failed", failed}};
    std::cerr << key << ": " << result[key].dump() << "\n";
  }
  result["settings"] = {{"count", count},
                        {"walk_samples_per_interval", kWalkSamples},
                        {"time", "wall time of BatchPlanner::plan (build, solve, validate)"}};
  std::cout << result.dump(2) << "\n\n";
  if (!json_path.empty()) std::ofstream(json_path) << result.dump(2) << "\n";

  const json& r = result["random_desk"];
  std::cout << "| random desk moves | success | without self / floor | clear successes | min self "
               "clearance (mm) | "
               "min floor clearance (mm) | median time (ms) | median horizon (s) |\n"
               "|---|---|---|---|---|---|---|---|\n";
  std::cout << "| " << r["cases"] << " | " << r["successes"] << " | "
            << r["successes_without_self_and_floor"] << " | " << r["successes_clear"] << " | "
            << cell(num(r["min_self_clearance_m"]), 1e3, 1) << " | "
            << cell(num(r["min_floor_clearance_m"]), 1e3, 1) << " | "
            << cell(num(r["time_s_median"]), 1e3) << " | " << cell(num(r["horizon_s_median"]), 1, 1)
            << " |\n\n";
  std::cout << "| problem | checks | success | median time (ms) | mean (ms) | max (ms) | median "
               "all runs (ms) | both valid: median (ms), ratio |\n"
               "|---|---|---|---|---|---|---|---|\n";
  for (const char* key : {"iiwa_task1", "iiwa_task2"}) {
    for (const char* mode : {"with", "without"}) {
      const json& s = result[key][mode];
      std::cout << "| " << key << " | " << mode << " | " << s["successes"] << "/" << s["runs"]
                << " | " << cell(num(s["time_s_median"]), 1e3) << " | "
                << cell(num(s["time_s_mean"]), 1e3) << " | " << cell(num(s["time_s_max"]), 1e3)
                << " | " << cell(num(s["time_s_median_all"]), 1e3) << " | "
                << cell(num(result[key][std::string("both_valid_") + mode + "_time_s_median"]), 1e3)
                << (std::string(mode) == "with"
                        ? ", " + cell(num(result[key]["both_valid_time_ratio_median"]), 1, 2)
                        : std::string())
                << " |\n";
    }
  }
  return 0;
}

}  // namespace
}  // namespace kinograph::bench

int main(int argc, char** argv) { return kinograph::bench::run(argc, argv); }

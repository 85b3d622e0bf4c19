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

#include "bench/common/bench_flags.h"
#include "bench/common/bench_stats.h"
#include "bench/common/clearance_walk.h"
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

// Points per interval of the clearance walk (the validator samples 10 and walks adaptively).
constexpr int kWalkSamples = 40;

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

int run(int argc, char** argv) {
  int count = 50;
  std::string json_path;
  if (!Flags("self_collision_bench")
           .value("--count", &count)
           .value("--json", &json_path)
           .parse(argc, argv)) {
    return 1;
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
      const Clearance cs = clearance_at(p, p.start_q), cg = clearance_at(p, p.goal.q);
      c["start_q"] = std::vector<double>(p.start_q.data(), p.start_q.data() + p.start_q.size());
      c["goal_q"] = std::vector<double>(p.goal.q.data(), p.goal.q.data() + p.goal.q.size());
      c["start_self_m"] = cs.self;
      c["start_floor_m"] = cs.floor;
      c["goal_self_m"] = cg.self;
      c["goal_floor_m"] = cg.floor;
      if (r.plan.success()) {
        ++ok;
        ok_times.push_back(r.wall_s);
        const Clearance cl = clearance_walk(p, r.plan, kWalkSamples);
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
        const Clearance c = clearance_walk(scene.problem, with[i].plan, kWalkSamples);
        if (c.self >= 0 && c.floor >= 0) ++with_clear;
      } else {
        const Clearance g = clearance_at(scene.problem, with[i].plan.q.bottomRows(1).transpose());
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
        const Clearance c = clearance_walk(scene.problem, without[i].plan, kWalkSamples);
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
            << cell(json_number(r["min_self_clearance_m"]), 1e3, 1) << " | "
            << cell(json_number(r["min_floor_clearance_m"]), 1e3, 1) << " | "
            << cell(json_number(r["time_s_median"]), 1e3) << " | "
            << cell(json_number(r["horizon_s_median"]), 1, 1) << " |\n\n";
  std::cout << "| problem | checks | success | median time (ms) | mean (ms) | max (ms) | median "
               "all runs (ms) | both valid: median (ms), ratio |\n"
               "|---|---|---|---|---|---|---|---|\n";
  for (const char* key : {"iiwa_task1", "iiwa_task2"}) {
    for (const char* mode : {"with", "without"}) {
      const json& s = result[key][mode];
      std::cout
          << "| " << key << " | " << mode << " | " << s["successes"] << "/" << s["runs"] << " | "
          << cell(json_number(s["time_s_median"]), 1e3) << " | "
          << cell(json_number(s["time_s_mean"]), 1e3) << " | "
          << cell(json_number(s["time_s_max"]), 1e3) << " | "
          << cell(json_number(s["time_s_median_all"]), 1e3) << " | "
          << cell(json_number(result[key][std::string("both_valid_") + mode + "_time_s_median"]),
                  1e3)
          << (std::string(mode) == "with"
                  ? ", " + cell(json_number(result[key]["both_valid_time_ratio_median"]), 1, 2)
                  : std::string())
          << " |\n";
    }
  }
  return 0;
}

}  // namespace
}  // namespace kinograph::bench

int main(int argc, char** argv) { return kinograph::bench::run(argc, argv); }

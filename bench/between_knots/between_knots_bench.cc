// The Acrobot swing-up (±8 N·m elbow, 10 s) planned at several grids, each plan measured
// between its knots independently of the planner: q sampled from the plan's interpolant at
// `--points` times inside every interval, q̇ and q̈ by central differences of those samples
// alone, τ by RNEA. Prints one JSON document, then a Markdown table; see README.md.
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench/common/bench_stats.h"
#include "bench/common/between_knots_measure.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/trajectory_sampler.h"

namespace kinograph::bench {
namespace {

using nlohmann::json;

int run(int argc, char** argv) {
  std::vector<int> grids = {50, 100, 200, 400};
  int repeats = 3, points = 10, refine_from = 100;
  std::string json_path;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--repeats" && i + 1 < argc) {
      repeats = std::stoi(argv[++i]);
    } else if (a == "--points" && i + 1 < argc) {
      points = std::stoi(argv[++i]);
    } else if (a == "--steps" && i + 1 < argc) {
      grids = {std::stoi(argv[++i])};
    } else if (a == "--refine-from" && i + 1 < argc) {
      refine_from = std::stoi(argv[++i]);
    } else if (a == "--json" && i + 1 < argc) {
      json_path = argv[++i];
    } else {
      std::cerr << "usage: between_knots_bench [--steps N] [--repeats N] [--points N] "
                   "[--refine-from N] [--json FILE]\n";
      return 1;
    }
  }
  spdlog::set_level(spdlog::level::warn);
  const planning::Scene scene = planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) +
                                                     "/robots/scenes/acrobot_swingup.yaml");
  const planning::BatchPlanner planner;
  json result = json::array();
  // Successful plans by grid: a finer grid is refined from the finest one that divides it
  // (its interpolant sampled at the finer knots), starting from the `refine_from` grid.
  std::map<int, planning::Plan> solved;
  planning::Problem coarse_problem = scene.problem;
  coarse_problem.steps = refine_from;
  const planning::Plan coarse = planner.plan(coarse_problem);
  if (coarse.success()) solved[refine_from] = coarse;
  std::vector<std::pair<int, bool>> cases;
  for (int steps : grids) {
    cases.push_back({steps, false});
    if (steps > refine_from && steps % refine_from == 0) cases.push_back({steps, true});
  }
  for (const auto& [steps, refined] : cases) {
    planning::Problem problem = scene.problem;
    problem.steps = steps;
    planning::Plan warm;
    int source = 0;
    if (refined) {
      for (const auto& [grid, plan] : solved) {
        if (grid < steps && steps % grid == 0) source = grid;
      }
      if (source == 0) continue;  // no coarser plan to refine from
      const planning::SampledPath path =
          planning::sample_plan(*problem.model, solved.at(source), steps / source);
      warm.t = path.t;
      warm.q = path.q;
      warm.qd = path.qd;
      warm.qdd = path.qdd;
      warm.tau = path.tau;
    }
    std::vector<double> times;
    planning::Plan plan;
    for (int r = 0; r < repeats; ++r) {
      const auto start = std::chrono::steady_clock::now();
      plan = planner.plan(problem, refined ? &warm : nullptr);
      times.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    json row = {{"steps", steps},
                {"init", refined ? "refined from " + std::to_string(source) + " steps"
                                 : std::string("straight line")},
                {"success", plan.success()},
                {"status", to_string(plan.stats.status)},
                {"time_s_median", median(times)},
                {"time_s_all", times},
                {"iterations", plan.stats.iterations},
                {"failures", plan.validation.failures}};
    if (plan.q.rows() == steps + 1) {
      const BetweenKnots m = measure_between_knots(*problem.model, plan, points);
      row["shoulder_torque_max"] = m.shoulder;
      row["elbow_torque_max"] = m.elbow_max;
      row["elbow_over_limit"] = m.elbow_excess;
      row["validator_tau_violation_between"] = plan.validation.max_tau_violation_between;
      row["validator_position_consistency"] = plan.validation.max_position_consistency;
    }
    if (plan.success() && (refined || solved.count(steps) == 0)) solved[steps] = plan;
    std::cerr << row.dump() << "\n";
    result.push_back(row);
  }
  const json out = {{"acrobot", result},
                    {"settings",
                     {{"scene", "robots/scenes/acrobot_swingup.yaml"},
                      {"repeats", repeats},
                      {"refine_from", refine_from},
                      {"points_per_interval", points},
                      {"time", "wall time of BatchPlanner::plan (build, solve, validate)"},
                      {"measure", "RNEA on central differences (±dt/200) of the interpolant's q"}}}};
  std::cout << out.dump(2) << "\n\n";
  if (!json_path.empty()) std::ofstream(json_path) << out.dump(2) << "\n";
  std::cout << "| steps | init | success | median time (ms) | max shoulder τ (N·m) | "
               "max elbow τ (N·m) | elbow over limit |\n|---|---|---|---|---|---|---|\n";
  for (const json& r : result) {
    const auto num = [&](const char* key) {
      return r.contains(key) ? r[key].get<double>() : std::nan("");
    };
    std::cout << "| " << r["steps"].get<int>() << " | " << r["init"].get<std::string>() << " | "
              << (r["success"].get<bool>() ? "yes" : "no")
              << " | " << cell(r["time_s_median"].get<double>(), 1e3) << " | "
              << cell(num("shoulder_torque_max"), 1, 4) << " | "
              << cell(num("elbow_torque_max"), 1, 3) << " | "
              << cell(std::max(0.0, num("elbow_over_limit")), 100, 2) << " % |\n";
  }
  return 0;
}

}  // namespace
}  // namespace kinograph::bench

int main(int argc, char** argv) { return kinograph::bench::run(argc, argv); }

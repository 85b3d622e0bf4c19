// The Acrobot swing-up (±8 N·m elbow, 10 s) planned at several grids, each plan measured
// between its knots independently of the planner: q sampled from the plan's interpolant at
// `--points` times inside every interval, q̇ and q̈ by central differences of those samples
// alone, τ by RNEA. Grids the planner refines are planned with the refinement off too. Prints
// one JSON document, then a Markdown table; see README.md.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench/common/bench_flags.h"
#include "bench/common/bench_stats.h"
#include "bench/common/between_knots_measure.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/batch/grid_refinement.h"
#include "kinograph/planning/io/scene.h"

namespace kinograph::bench {
namespace {

using nlohmann::json;

int run(int argc, char** argv) {
  std::vector<int> grids = {50, 100, 200, 400};
  int repeats = 3, points = 10;
  std::string json_path;
  int steps = 0;
  if (!bench::Flags("between_knots_bench")
           .value("--steps", &steps)
           .value("--repeats", &repeats)
           .value("--points", &points)
           .value("--json", &json_path)
           .parse(argc, argv)) {
    return 64;
  }
  if (steps > 0) grids = {steps};
  if (repeats < 1 || points < 0 || steps < 0) {
    std::cerr << "between_knots_bench: --repeats must be at least 1, --steps and --points "
                 "not negative\n";
    return 64;
  }
  spdlog::set_level(spdlog::level::warn);
  const planning::Scene scene = planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) +
                                                     "/robots/scenes/acrobot_swingup.yaml");
  planning::BatchPlannerOptions direct;
  direct.refine_max_interval = 0;
  const planning::BatchPlanner planner, direct_planner(direct);
  json result = json::array();
  // Each grid with the planner as it is; a grid it refines also with the refinement off.
  std::vector<std::pair<int, bool>> cases;
  for (int steps : grids) {
    planning::Problem problem = scene.problem;
    problem.steps = steps;
    cases.push_back({steps, true});
    if (planning::coarser_grid(problem, planner.options().refine_max_interval) > 0) {
      cases.push_back({steps, false});
    }
  }
  for (const auto& [steps, refining] : cases) {
    planning::Problem problem = scene.problem;
    problem.steps = steps;
    const planning::BatchPlanner& p = refining ? planner : direct_planner;
    std::vector<double> times;
    planning::Plan plan;
    for (int r = 0; r < repeats; ++r) {
      const auto start = std::chrono::steady_clock::now();
      plan = p.plan(problem);
      times.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    json row = {{"steps", steps},
                {"planner", refining ? "as it is" : "refinement off"},
                {"success", plan.success()},
                {"status", to_string(plan.stats.status)},
                {"time_s_median", median(times)},
                {"time_s_all", times},
                {"iterations", plan.stats.iterations},
                {"attempts", plan.stats.attempts},
                {"failures", plan.validation.failures}};
    if (plan.q.rows() == steps + 1) {
      const BetweenKnots m = measure_between_knots(*problem.model, plan, points);
      row["shoulder_torque_max"] = m.shoulder;
      row["elbow_torque_max"] = m.elbow_max;
      row["elbow_over_limit"] = m.elbow_excess;
      row["validator_tau_violation_between"] = plan.validation.max_tau_violation_between;
      row["validator_position_consistency"] = plan.validation.max_position_consistency;
    }
    std::cerr << row.dump() << "\n";
    result.push_back(row);
  }
  const json out = {
      {"acrobot", result},
      {"settings",
       {{"scene", "robots/scenes/acrobot_swingup.yaml"},
        {"repeats", repeats},
        {"points_per_interval", points},
        {"time", "wall time of BatchPlanner::plan (coarse grids, build, solve, validate)"},
        {"measure", "RNEA on central differences (±dt/200) of the interpolant's q"}}}};
  std::cout << out.dump(2) << "\n\n";
  if (!json_path.empty()) std::ofstream(json_path) << out.dump(2) << "\n";
  std::cout << "| steps | planner | success | solver status | LM iterations | median time (ms) | "
               "max shoulder τ (N·m) | max elbow τ (N·m) | elbow over limit |\n"
               "|---|---|---|---|---|---|---|---|---|\n";
  for (const json& r : result) {
    const auto num = [&](const char* key) {
      return r.contains(key) ? r[key].get<double>() : std::nan("");
    };
    std::cout << "| " << r["steps"].get<int>() << " | " << r["planner"].get<std::string>()
              << " | " << (r["success"].get<bool>() ? "yes" : "no") << " | "
              << r["status"].get<std::string>() << " | " << r["iterations"].get<int>() << " | "
              << cell(r["time_s_median"].get<double>(), 1e3) << " | "
              << cell(num("shoulder_torque_max"), 1, 4) << " | "
              << cell(num("elbow_torque_max"), 1, 3) << " | "
              << cell(std::max(0.0, num("elbow_over_limit")), 100, 2) << " % |\n";
  }
  return 0;
}

}  // namespace
}  // namespace kinograph::bench

int main(int argc, char** argv) { return kinograph::bench::run(argc, argv); }

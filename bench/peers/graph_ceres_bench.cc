// kinograph's Levenberg–Marquardt against Ceres's on the graph the planner really solves: the
// iiwa task-1 planning graph (the desk scene, seeded goals), the same factors through an
// adapter, the same start and the same stopping rule. Every augmented-Lagrangian round of the
// batch planner's outer loop is one inner problem: both solvers start from the same iterate
// and multipliers; the loop then goes on from kinograph's result.
#include <ceres/ceres.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench/common/bench_flags.h"
#include "bench/common/bench_stats.h"
#include "bench/common/cpu_clock.h"
#include "bench/common/iiwa_goals.h"
#include "kinograph/graph/levenberg_marquardt.h"
#include "kinograph/planning/formulation/initialization.h"
#include "kinograph/planning/formulation/planning_graph.h"
#include "kinograph/planning/goal_sampler.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/solver/augmented_lagrangian.h"
#include "tests/graph/problems.h"

using kinograph::bench::cell;
using kinograph::bench::median;
using nlohmann::json;
namespace planning = kinograph::planning;
namespace graph = kinograph::graph;

namespace {

using kinograph::bench::cpu_seconds;

/// One inner problem solved by both: CPU times, final costs (both ½‖r‖²), iterations.
struct Inner {
  double ours_s = 0, ceres_s = 0, ours_cost = 0, ceres_cost = 0, initial_cost = 0;
  int ours_iterations = 0, ceres_iterations = 0;
};

/// The rounds of one planning problem, at most `rounds` of them (fewer when the outer loop
/// converges earlier).
std::vector<Inner> solve_rounds(const planning::Problem& problem, int rounds, double tolerance) {
  const Eigen::VectorXd goal = *planning::goal_configuration(problem);
  planning::PlanningGraph pg =
      planning::build_graph(problem, planning::straight_line(problem, goal));
  planning::ConstraintState state;
  planning::AugmentedLagrangian al(pg.constraints(false), state);
  graph::LevenbergMarquardtOptions options;
  options.record_history = false;
  options.relative_error_tol = tolerance;
  const planning::OuterLoopOptions loop;
  std::vector<Inner> out;
  for (int r = 0; r < rounds; ++r) {
    Inner inner;
    {
      Eigen::VectorXd params;
      ceres::Problem cp;
      graph::problems::build_ceres(pg.graph, pg.values, params, cp);
      ceres::Solver::Summary summary;
      const double t = cpu_seconds();
      ceres::Solve(
          graph::problems::ceres_options(tolerance, options.step_tol, options.lambda_initial), &cp,
          &summary);
      inner.ceres_s = cpu_seconds() - t;
      inner.ceres_cost = summary.final_cost;
      inner.initial_cost = summary.initial_cost;
      inner.ceres_iterations = static_cast<int>(summary.iterations.size()) - 1;
    }
    {
      graph::LevenbergMarquardt lm(options);  // cold: ordering and symbolic analysis included
      const double t = cpu_seconds();
      const graph::OptimizationResult res = lm.optimize(pg.graph, pg.values);
      inner.ours_s = cpu_seconds() - t;
      inner.ours_cost = res.final_error;
      inner.ours_iterations = res.iterations;
    }
    out.push_back(inner);
    if (al.report(pg.values).scaled_violation <= loop.constraint_tolerance) break;
    al.update(pg.values);
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  int goals = 20, rounds = 8;
  // Tight, so that both solvers end at the same minimum (to 1e-6) where there is one.
  double tolerance = 1e-10;
  std::string json_path;
  kinograph::bench::Flags flags("graph_ceres_bench");
  flags.value("--goals", &goals)
      .value("--rounds", &rounds)
      .value("--tolerance", &tolerance)
      .value("--json", &json_path);
  if (!flags.parse(argc, argv)) return 64;
  spdlog::set_level(spdlog::level::warn);

  const planning::Scene desk = planning::load_scene(kinograph::bench::kScenes + "iiwa_desk.yaml");
  planning::GoalSampler sampler(desk.problem, kinograph::bench::iiwa_goal_options(1));
  std::vector<double> ours, theirs, ratio, cost_gap;
  int rounds_total = 0, rounds_same_cost = 0;
  json problems = json::array();
  int variables = 0, factors = 0;
  for (const Eigen::VectorXd& q : sampler.sample(goals)) {
    planning::Problem problem = desk.problem;
    problem.goal.q = q;
    const std::vector<Inner> inner = solve_rounds(problem, rounds, tolerance);
    double o = 0, c = 0, gap = 0;
    json per_round = json::array();
    for (const Inner& r : inner) {
      o += r.ours_s;
      c += r.ceres_s;
      const double g = std::abs(r.ours_cost - r.ceres_cost) / std::max(r.ours_cost, r.ceres_cost);
      gap = std::max(gap, g);
      ++rounds_total;
      if (g <= 1e-6) ++rounds_same_cost;
      per_round.push_back({{"kinograph_s", r.ours_s},
                           {"ceres_s", r.ceres_s},
                           {"initial_cost", r.initial_cost},
                           {"kinograph_cost", r.ours_cost},
                           {"ceres_cost", r.ceres_cost},
                           {"kinograph_iterations", r.ours_iterations},
                           {"ceres_iterations", r.ceres_iterations}});
    }
    ours.push_back(o);
    theirs.push_back(c);
    ratio.push_back(c / o);
    cost_gap.push_back(gap);
    problems.push_back({{"kinograph_s", o}, {"ceres_s", c}, {"rounds", per_round}});
    std::cerr << "goal " << problems.size() << ": kinograph " << 1e3 * o << " ms CPU, Ceres "
              << 1e3 * c << " ms CPU\n";
  }
  {
    const Eigen::VectorXd goal = *planning::goal_configuration(desk.problem);
    const planning::PlanningGraph pg =
        planning::build_graph(desk.problem, planning::straight_line(desk.problem, goal));
    variables = pg.values.total_dim();
    factors = static_cast<int>(pg.graph.num_factors());
  }
  const json result = {{"goals", problems.size()},
                       {"max_rounds", rounds},
                       {"relative_tolerance", tolerance},
                       {"graph_scalars", variables},
                       {"graph_factors", factors},
                       {"kinograph_median_s", median(ours)},
                       {"ceres_median_s", median(theirs)},
                       {"median_ratio_ceres_over_kinograph", median(ratio)},
                       {"rounds", rounds_total},
                       {"rounds_same_final_cost_1e-6", rounds_same_cost},
                       {"median_max_relative_cost_gap", median(cost_gap)},
                       {"max_relative_cost_gap", kinograph::bench::max_of(cost_gap)},
                       {"problems", problems}};
  if (!json_path.empty()) std::ofstream(json_path) << result.dump(2) << "\n";
  std::printf(
      "| graph | problems (rounds) | kinograph median CPU (ms) | Ceres median CPU (ms) | Ceres / "
      "kinograph (median of ratios) | rounds ending at the same cost (1e-6) |\n");
  std::printf("|---|---|---|---|---|---|\n");
  std::printf("| iiwa task 1, %d scalars, %d factors | %zu (%d) | %s | %s | %s | %d of %d |\n",
              variables, factors, problems.size(), rounds_total, cell(median(ours), 1e3, 1).c_str(),
              cell(median(theirs), 1e3, 1).c_str(), cell(median(ratio), 1, 2).c_str(),
              rounds_same_cost, rounds_total);
  return 0;
}

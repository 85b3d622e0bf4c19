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

/// A solver's progress: cost after each accepted step against the wall time since the start.
using Progress = std::vector<std::pair<double, double>>;  // (seconds, cost)

/// The share of a solve's wall time spent before its cost first came within `target`.
double share_to_reach(const Progress& progress, double total_wall_s, double target) {
  for (const auto& [t, cost] : progress) {
    if (cost <= target) return total_wall_s > 0 ? std::min(1.0, t / total_wall_s) : 1.0;
  }
  return 1.0;
}

/// Records Ceres's cost after every iteration (its cumulative time includes preprocessing).
class CeresProgress : public ceres::IterationCallback {
 public:
  explicit CeresProgress(Progress& out) : out_(out) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    out_.emplace_back(s.cumulative_time_in_seconds, s.cost);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  Progress& out_;
};

/// One inner problem solved by both: CPU times, final costs (both ½‖r‖²), iterations, and the
/// CPU time each took to come within 1e-6 of the higher of the two final costs (the cost both
/// reached), estimated as its CPU time × the share of its wall time spent before it got there.
struct Inner {
  double ours_s = 0, ceres_s = 0, ours_cost = 0, ceres_cost = 0, initial_cost = 0;
  double ours_to_common_s = 0, ceres_to_common_s = 0;
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
  options.record_history = true;
  options.relative_error_tol = tolerance;
  options.threads = 1;  // as Ceres: one thread each
  const planning::OuterLoopOptions loop;
  std::vector<Inner> out;
  for (int r = 0; r < rounds; ++r) {
    Inner inner;
    Progress ceres_progress, ours_progress;
    double ceres_wall = 0, ours_wall = 0;
    {
      Eigen::VectorXd params;
      ceres::Problem cp;
      graph::problems::build_ceres(pg.graph, pg.values, params, cp);
      ceres::Solver::Summary summary;
      ceres::Solver::Options ceres_options =
          graph::problems::ceres_options(tolerance, options.step_tol, options.lambda_initial);
      CeresProgress callback(ceres_progress);
      ceres_options.callbacks.push_back(&callback);
      const double t = cpu_seconds();
      ceres::Solve(ceres_options, &cp, &summary);
      inner.ceres_s = cpu_seconds() - t;
      ceres_wall = summary.total_time_in_seconds;
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
      ours_wall = res.total_s;
      double elapsed = res.symbolic_s;
      ours_progress.emplace_back(elapsed, res.initial_error);
      for (const graph::IterationStats& h : res.history) {
        elapsed += h.linearize_s + h.factorize_s + h.solve_s + h.evaluate_s;
        if (h.accepted) ours_progress.emplace_back(elapsed, h.error);
      }
    }
    const double common = std::max(inner.ours_cost, inner.ceres_cost) * (1 + 1e-6);
    inner.ours_to_common_s = inner.ours_s * share_to_reach(ours_progress, ours_wall, common);
    inner.ceres_to_common_s = inner.ceres_s * share_to_reach(ceres_progress, ceres_wall, common);
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
  std::vector<double> ours, theirs, ratio, cost_gap, ours_common, theirs_common, ratio_common;
  int rounds_total = 0, rounds_same_cost = 0;
  json problems = json::array();
  int variables = 0, factors = 0;
  for (const Eigen::VectorXd& q : sampler.sample(goals)) {
    planning::Problem problem = desk.problem;
    problem.goal.q = q;
    const std::vector<Inner> inner = solve_rounds(problem, rounds, tolerance);
    double o = 0, c = 0, gap = 0, oc = 0, cc = 0;
    json per_round = json::array();
    for (const Inner& r : inner) {
      o += r.ours_s;
      c += r.ceres_s;
      oc += r.ours_to_common_s;
      cc += r.ceres_to_common_s;
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
    ours_common.push_back(oc);
    theirs_common.push_back(cc);
    ratio_common.push_back(cc / oc);
    cost_gap.push_back(gap);
    problems.push_back({{"kinograph_s", o},
                        {"ceres_s", c},
                        {"kinograph_to_common_cost_s", oc},
                        {"ceres_to_common_cost_s", cc},
                        {"rounds", per_round}});
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
                       {"kinograph_to_common_cost_median_s", median(ours_common)},
                       {"ceres_to_common_cost_median_s", median(theirs_common)},
                       {"median_ratio_to_common_cost", median(ratio_common)},
                       {"rounds", rounds_total},
                       {"rounds_same_final_cost_1e-6", rounds_same_cost},
                       {"median_max_relative_cost_gap", median(cost_gap)},
                       {"max_relative_cost_gap", kinograph::bench::max_of(cost_gap)},
                       {"problems", problems}};
  if (!json_path.empty()) std::ofstream(json_path) << result.dump(2) << "\n";
  std::printf(
      "| graph | problems (rounds) | measure | kinograph median CPU (ms) | "
      "Ceres median CPU (ms) | Ceres / kinograph (median of ratios) |\n");
  std::printf("|---|---|---|---|---|---|\n");
  std::printf(
      "| iiwa task 1, %d scalars, %d factors | %zu (%d) | to its own stop | %s | %s | %s |\n",
      variables, factors, problems.size(), rounds_total, cell(median(ours), 1e3, 1).c_str(),
      cell(median(theirs), 1e3, 1).c_str(), cell(median(ratio), 1, 2).c_str());
  std::printf("| | | to the cost both reach (1e-6) | %s | %s | %s |\n",
              cell(median(ours_common), 1e3, 1).c_str(),
              cell(median(theirs_common), 1e3, 1).c_str(),
              cell(median(ratio_common), 1, 2).c_str());
  std::printf("\nRounds whose two final costs agree within 1e-6: %d of %d.\n", rounds_same_cost,
              rounds_total);
  return 0;
}

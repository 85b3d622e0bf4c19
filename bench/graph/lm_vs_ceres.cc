// kinograph's batch LM against Ceres (LM, SPARSE_NORMAL_CHOLESKY on SuiteSparse) on the same
// problems, residual code, start and stopping rule, in one run. Prints a Markdown table and
// writes JSON (medians over repetitions, ratio kinograph/Ceres, per-iteration breakdown).
//
//   graph_lm_vs_ceres [--reps 7] [--chain 10000] [--steps 99] [--json bench_graph.json]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench/graph/planning_problem.h"
#include "kinograph/graph/levenberg_marquardt.h"
#include "tests/graph/problems.h"

using namespace kinograph::graph;
using Clock = std::chrono::steady_clock;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n == 0 ? 0 : (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}

struct Row {
  std::string problem;
  std::string variant;
  int variables = 0, scalars = 0, factors = 0;
  std::vector<double> ours_s, ceres_s, ours_warm_s;
  double ours_cost = 0, ceres_cost = 0, initial_cost = 0;
  int ours_iterations = 0, ours_trials = 0, ceres_iterations = 0, ceres_successful = 0;
  std::string ours_status, factorization;
  // Per-iteration breakdown (medians over repetitions of the per-solve means), milliseconds.
  std::vector<double> lin_ms, fact_ms, solve_ms, eval_ms, symbolic_ms;
  std::vector<double> ceres_jac_ms, ceres_linear_ms, ceres_residual_ms, ceres_pre_ms;
};

Row run(const std::string& name, const problems::Problem& p, int reps,
        const LevenbergMarquardtOptions& options, const std::string& variant) {
  Row row;
  row.problem = name;
  row.variant = variant;
  row.variables = p.start.size();
  row.scalars = p.start.total_dim();
  row.factors = static_cast<int>(p.graph.num_factors());
  for (int rep = 0; rep < reps; ++rep) {
    // kinograph, cold: structure, ordering and symbolic analysis included, as Ceres' are.
    {
      Values v = p.start;
      LevenbergMarquardt lm(options);
      const auto t = Clock::now();
      const auto r = lm.optimize(p.graph, v);
      row.ours_s.push_back(std::chrono::duration<double>(Clock::now() - t).count());
      row.ours_cost = r.final_error;
      row.initial_cost = r.initial_error;
      row.ours_iterations = r.iterations;
      row.ours_trials = r.trials;
      row.ours_status = to_string(r.status);
      row.factorization =
          lm.cholesky() && lm.cholesky()->is_supernodal() ? "supernodal" : "simplicial";
      row.lin_ms.push_back(1e3 * r.linearize_s / r.iterations);
      row.fact_ms.push_back(1e3 * r.factorize_s / r.trials);
      row.solve_ms.push_back(1e3 * r.solve_s / r.trials);
      row.eval_ms.push_back(1e3 * r.evaluate_s / r.trials);
      row.symbolic_ms.push_back(1e3 * r.symbolic_s);
      // Warm: the same solver again from the start (structure cached), the planner's re-solve.
      Values w = p.start;
      const auto t2 = Clock::now();
      lm.optimize(p.graph, w);
      row.ours_warm_s.push_back(std::chrono::duration<double>(Clock::now() - t2).count());
    }
    // Ceres, same residual code through an adapter.
    {
      ceres::Problem problem;
      Eigen::VectorXd params;
      problems::build_ceres(p.graph, p.start, params, problem);
      ceres::Solver::Summary summary;
      const auto t = Clock::now();
      ceres::Solve(problems::ceres_options(options.relative_error_tol, options.step_tol,
                                           options.lambda_initial),
                   &problem, &summary);
      row.ceres_s.push_back(std::chrono::duration<double>(Clock::now() - t).count());
      row.ceres_cost = summary.final_cost;
      row.ceres_iterations = static_cast<int>(summary.iterations.size()) - 1;
      row.ceres_successful = summary.num_successful_steps;
      const double its = std::max(1, row.ceres_iterations);
      row.ceres_jac_ms.push_back(1e3 * summary.jacobian_evaluation_time_in_seconds /
                                 std::max(1, summary.num_jacobian_evaluations));
      row.ceres_linear_ms.push_back(1e3 * summary.linear_solver_time_in_seconds /
                                    std::max(1, summary.num_linear_solves));
      row.ceres_residual_ms.push_back(1e3 * summary.residual_evaluation_time_in_seconds / its);
      row.ceres_pre_ms.push_back(1e3 * summary.preprocessor_time_in_seconds);
    }
  }
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 7, chain_n = 10000, steps = 99;
  std::string json_path = "bench_graph.json";
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--reps"))
      reps = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--chain"))
      chain_n = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--steps"))
      steps = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--json"))
      json_path = argv[i + 1];
  }
  std::vector<Row> rows;
  LevenbergMarquardtOptions defaults;  // the paper's: λ₀ 0.01, 200 iterations, 1e-5
  defaults.threads = 1;                 // as Ceres: one thread each
  rows.push_back(run("curve_fit", problems::curve_fit(), reps, defaults, "auto"));
  const auto chain = problems::chain(chain_n);
  rows.push_back(run("chain", chain, reps, defaults, "auto"));
  for (int dof : {2, 7}) {  // Acrobot-sized and iiwa-sized
    const auto plan = bench::planning_problem(steps, dof);
    const std::string name = "planning_n" + std::to_string(dof);
    for (auto f : {Factorization::kAuto, Factorization::kSimplicial, Factorization::kSupernodal}) {
      LevenbergMarquardtOptions o;
      o.factorization = f;
      o.threads = 1;
      rows.push_back(run(name, plan, reps, o, to_string(f)));
    }
  }

  nlohmann::json out = nlohmann::json::array();
  std::printf(
      "| problem | factorization | vars (scalars) | kinograph ms | Ceres ms | ratio | warm ms | "
      "cost kinograph | cost Ceres | its (trials) / Ceres its | lin ms/it | fact ms/trial | "
      "solve ms/trial | eval ms/trial | Ceres jac ms | Ceres linear ms |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    const double ours = 1e3 * median(r.ours_s), theirs = 1e3 * median(r.ceres_s);
    std::printf(
        "| %s | %s (%s) | %d (%d) | %.3f | %.3f | %.3f | %.3f | %.10g | %.10g | %d (%d) / %d | "
        "%.4f | %.4f | %.4f | %.4f | %.4f | %.4f |\n",
        r.problem.c_str(), r.variant.c_str(), r.factorization.c_str(), r.variables, r.scalars, ours,
        theirs, ours / theirs, 1e3 * median(r.ours_warm_s), r.ours_cost, r.ceres_cost,
        r.ours_iterations, r.ours_trials, r.ceres_iterations, median(r.lin_ms), median(r.fact_ms),
        median(r.solve_ms), median(r.eval_ms), median(r.ceres_jac_ms), median(r.ceres_linear_ms));
    out.push_back({{"problem", r.problem},
                   {"factorization_option", r.variant},
                   {"factorization_used", r.factorization},
                   {"variables", r.variables},
                   {"scalars", r.scalars},
                   {"factors", r.factors},
                   {"repetitions", r.ours_s.size()},
                   {"kinograph_ms_median", ours},
                   {"ceres_ms_median", theirs},
                   {"ratio_kinograph_over_ceres", ours / theirs},
                   {"kinograph_warm_ms_median", 1e3 * median(r.ours_warm_s)},
                   {"kinograph_status", r.ours_status},
                   {"initial_cost", r.initial_cost},
                   {"kinograph_final_cost", r.ours_cost},
                   {"ceres_final_cost", r.ceres_cost},
                   {"kinograph_iterations", r.ours_iterations},
                   {"kinograph_trials", r.ours_trials},
                   {"ceres_iterations", r.ceres_iterations},
                   {"ceres_successful_steps", r.ceres_successful},
                   {"kinograph_per_iteration_ms",
                    {{"linearize", median(r.lin_ms)},
                     {"factorize", median(r.fact_ms)},
                     {"solve", median(r.solve_ms)},
                     {"evaluate", median(r.eval_ms)},
                     {"symbolic_once", median(r.symbolic_ms)},
                     {"total_per_trial", ours / r.ours_trials}}},
                   {"ceres_per_iteration_ms",
                    {{"jacobian_evaluation", median(r.ceres_jac_ms)},
                     {"linear_solve", median(r.ceres_linear_ms)},
                     {"residual_evaluation", median(r.ceres_residual_ms)},
                     {"preprocessor_once", median(r.ceres_pre_ms)},
                     {"total_per_iteration", theirs / std::max(1, r.ceres_iterations)}}}});
  }
  std::ofstream(json_path) << out.dump(2) << "\n";
  std::printf("\nJSON written to %s\n", json_path.c_str());
  return 0;
}

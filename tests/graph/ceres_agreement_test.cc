// Nonlinear problems: kinograph's LM reaches the same optimum as Ceres (LM, sparse normal
// Cholesky on SuiteSparse) from the same start, with the same residual code.
#include <gtest/gtest.h>

#include "kinograph/graph/levenberg_marquardt.h"
#include "tests/graph/problems.h"

namespace kinograph::graph {
namespace {

struct Both {
  OptimizationResult ours;
  Values ours_values;
  ceres::Solver::Summary theirs;
  Eigen::VectorXd theirs_params;
};

// tol: relative cost decrease; step_tol: relative step size (both solvers use both rules).
Both solve_both(const problems::Problem& p, double tol, double step_tol) {
  Both out;
  out.ours_values = p.start;
  LevenbergMarquardtOptions o;
  o.relative_error_tol = tol;
  o.step_tol = step_tol;
  out.ours = LevenbergMarquardt(o).optimize(p.graph, out.ours_values);
  ceres::Problem problem;
  problems::build_ceres(p.graph, p.start, out.theirs_params, problem);
  ceres::Solve(problems::ceres_options(tol, step_tol), &problem, &out.theirs);
  return out;
}

TEST(CeresAgreement, CurveFitReachesTheSameOptimum) {
  const auto p = problems::curve_fit();
  const auto both = solve_both(p, 0, 1e-10);
  ASSERT_TRUE(both.ours.converged()) << both.ours.reason;
  ASSERT_TRUE(both.theirs.IsSolutionUsable());
  EXPECT_NEAR(both.ours.final_error, both.theirs.final_cost, 1e-12 * both.theirs.final_cost);
  EXPECT_NEAR(both.ours.initial_error, both.theirs.initial_cost, 1e-12 * both.theirs.initial_cost);
  EXPECT_LT((both.ours_values.vector() - both.theirs_params).norm(), 1e-8);
  // And it is the curve the data came from, within the noise.
  EXPECT_NEAR(both.ours_values.vector()[0], 0.3, 0.02);
  EXPECT_NEAR(both.ours_values.vector()[1], 0.1, 0.1);
}

TEST(CeresAgreement, ChainOfThousandsReachesTheSameOptimum) {
  const auto p = problems::chain(2000);
  const auto both = solve_both(p, 0, 1e-10);
  ASSERT_TRUE(both.ours.converged()) << both.ours.reason;
  ASSERT_TRUE(both.theirs.IsSolutionUsable());
  EXPECT_NEAR(both.ours.final_error, both.theirs.final_cost, 1e-12 * both.theirs.final_cost);
  // Linear convergence on a non-zero-residual problem: x agrees to what the cost resolves.
  EXPECT_LT((both.ours_values.vector() - both.theirs_params).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_LT(both.ours.final_error, 0.5 * both.ours.initial_error);
}

TEST(CeresAgreement, PaperStoppingRuleEndsNearTheSameCost) {
  // With the paper's tolerance (relative decrease 1e-5) both stop close to the optimum.
  const auto p = problems::chain(2000);
  const auto both = solve_both(p, 1e-5, 1e-14);
  ASSERT_TRUE(both.ours.converged()) << both.ours.reason;
  EXPECT_NEAR(both.ours.final_error, both.theirs.final_cost, 1e-5 * both.theirs.final_cost);
}

}  // namespace
}  // namespace kinograph::graph

// The batch planner's two formulations of the equations of motion — condensed (τ = RNEA per
// step) and the full dynamic factor graph — pose the same problem and must give the same plan.
#include <gtest/gtest.h>

#include "kinograph/planning/batch/batch_planner.h"
#include "tests/planning/test_problems.h"

namespace kinograph::planning {
namespace {

// Options that solve each plan to a tight optimum: the defaults stop at the first feasible plan
// with a loose objective tolerance, where two solvers' plans may differ along the flat objective.
BatchPlannerOptions tight() {
  BatchPlannerOptions o;
  o.outer_loop.constraint_tolerance = 1e-5;
  o.outer_loop.inner_tolerance_final = 1e-8;
  o.outer_loop.max_outer_iterations = 30;
  o.outer_loop.max_total_iterations = 1500;
  return o;
}

// Plans `problem` in both formulations and checks that both validate and agree. They agree to
// the convergence tolerances, not to rounding: the inner LM solves stop at a relative decrease,
// and the DFG's extra variables change the path LM takes to the same optimum.
void expect_same_plans(const Problem& problem, double q_tol, double tau_tol,
                       int interval_samples = ValidationThresholds().interval_samples) {
  BatchPlannerOptions condensed = tight();
  condensed.validation.interval_samples = interval_samples;
  BatchPlannerOptions dfg = condensed;
  dfg.formulation = Formulation::kDynamicFactorGraph;
  const Plan a = BatchPlanner(condensed).plan(problem);
  const Plan b = BatchPlanner(dfg).plan(problem);
  for (const auto& f : a.validation.failures) ADD_FAILURE() << "condensed: " << f;
  for (const auto& f : b.validation.failures) ADD_FAILURE() << "dfg: " << f;
  ASSERT_TRUE(a.success());
  ASSERT_TRUE(b.success());
  // The DFG's τ are its own variables: the validator's dynamics residual checks them.
  EXPECT_LT(b.validation.max_dynamics_residual, 1e-3);
  EXPECT_LT((a.q - b.q).cwiseAbs().maxCoeff(), q_tol);
  EXPECT_LT((a.qd - b.qd).cwiseAbs().maxCoeff(), 3 * q_tol);
  EXPECT_LT((a.tau - b.tau).cwiseAbs().maxCoeff(), tau_tol);
  EXPECT_NEAR(a.stats.cost, b.stats.cost, 1e-3 * (1 + a.stats.cost));
}

TEST(Formulation, Names) {
  EXPECT_EQ(to_string(Formulation::kCondensed), "condensed");
  EXPECT_EQ(to_string(Formulation::kDynamicFactorGraph), "dfg");
}

TEST(Formulation, RrReachIsTheSamePlan) {
  Problem p = testing::rr_reach();
  p.obstacles.clear();  // with the ball, the two solvers' paths may pass it on different sides
  expect_same_plans(p, 3e-3, 2e-2);
}

TEST(Formulation, DfgWithDefaultOptionsValidates) {
  BatchPlannerOptions dfg;
  dfg.formulation = Formulation::kDynamicFactorGraph;
  const Plan plan = BatchPlanner(dfg).plan(testing::iiwa_swing(12));
  for (const auto& f : plan.validation.failures) ADD_FAILURE() << f;
  EXPECT_TRUE(plan.success());
}

TEST(Formulation, DfgAvoidsTheBall) {
  BatchPlannerOptions dfg;
  dfg.formulation = Formulation::kDynamicFactorGraph;
  const Plan plan = BatchPlanner(dfg).plan(testing::rr_reach());
  for (const auto& f : plan.validation.failures) ADD_FAILURE() << f;
  EXPECT_TRUE(plan.success());
  EXPECT_GE(plan.validation.min_clearance, 0.0);
}

TEST(Formulation, IiwaWithBlockIsTheSamePlan) {
  // At the knots only: the between-knot limit points come in by constraint generation, whose
  // re-solve projects onto the rows it adds rather than polishing the objective, so the two
  // formulations' plans meet only as well as the intervals each flagged.
  Problem p = testing::iiwa_swing(12);
  p.objectives.limit_substeps = 0;
  expect_same_plans(p, 3e-3, 2e-2, 1);
}

TEST(Formulation, MinimumTorqueRowsAreTheSame) {
  Problem p = testing::iiwa_swing(12);
  p.objectives.min_torque = 1e-3;
  // Without the between-knot limit points (planned and validated at the knots only): some are
  // active on this swing, and with them the minimum-torque optimum is too flat for the two
  // solvers' paths to meet within 3e-3 rad.
  p.objectives.limit_substeps = 0;
  expect_same_plans(p, 3e-3, 2e-2, 1);
}

}  // namespace
}  // namespace kinograph::planning

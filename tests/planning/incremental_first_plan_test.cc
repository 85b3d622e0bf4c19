// iDFGP's first plan: the batch planner's plan carried into the incremental graph (its factors,
// values and multipliers; no second solve), and a Bayes tree that starts at that plan.
#include <gtest/gtest.h>

#include <string>

#include "bench/common/iiwa_goals.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/goal_sampler.h"
#include "kinograph/planning/incremental/first_plan.h"
#include "kinograph/planning/incremental/incremental_planner.h"
#include "kinograph/planning/io/scene.h"

#include "tests/planning/test_problems.h"

namespace kinograph::planning {
namespace {

using testing::failures;

const std::string kScenes = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/";

double max_abs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }

using testing::tip_goal;

// The RR reach with its ball, and the same with the goal as the tip's position at the joint goal.
Problem rr_joint_goal() { return load_scene(kScenes + "rr_reach.yaml").problem; }
Problem rr_pose_goal() {
  Problem p = rr_joint_goal();
  p.goal = tip_goal(p, p.goal.q);
  return p;
}

// Without settling, the first plan is the batch planner's plan itself. The carried multipliers
// hold the Bayes tree at it: a replan of the unchanged problem needs no multiplier round and
// moves no farther than the batch plan is from the optimum of a tightly converged batch solve
// (the batch planner stops its last LM solve at a relative decrease of 1e-3), toward it.
void expect_carried(const Problem& p) {
  const Plan batch = BatchPlanner().plan(p);
  ASSERT_TRUE(batch.success()) << failures(batch);
  BatchPlannerOptions tight_options;
  tight_options.outer_loop.inner_tolerance_final = 1e-8;
  tight_options.outer_loop.constraint_tolerance = 1e-6;
  tight_options.outer_loop.max_outer_iterations = 40;
  const Plan tight = BatchPlanner(tight_options).plan(p);
  ASSERT_TRUE(tight.success()) << failures(tight);

  IncrementalPlannerOptions options;
  options.settle_first_plan = false;
  options.stop_at_first_valid = false;  // converge (any multiplier error then shows as a round)
  IncrementalPlanner planner(options);
  const Plan first = planner.plan(p);
  ASSERT_TRUE(first.success()) << failures(first);
  EXPECT_EQ(first.stats.method, batch.stats.method);
  EXPECT_EQ(max_abs(first.q - batch.q), 0.0);
  EXPECT_EQ(max_abs(first.tau - batch.tau), 0.0);
  EXPECT_EQ(first.stats.cost, batch.stats.cost);
  EXPECT_EQ(first.stats.iterations, batch.stats.iterations) << "no second solve";
  ASSERT_TRUE(planner.has_plan());

  const Plan same = planner.replan(ProblemChange());
  ASSERT_TRUE(same.success()) << failures(same);
  EXPECT_EQ(planner.last_stats().rounds, 0) << "the carried multipliers needed no update";
  // Converging an unchanged problem to the final tolerance: a few updates (4 with ISAM2's
  // λ schedule at the time of writing), not a re-solve.
  EXPECT_LE(planner.last_stats().updates, 5);
  const double gap = max_abs(batch.q - tight.q);
  EXPECT_LT(max_abs(same.q - batch.q), gap + 1e-3) << "batch plan " << gap << " from the optimum";
  EXPECT_LT(max_abs(same.q - tight.q), gap + 1e-3);
  EXPECT_NEAR(same.stats.cost, batch.stats.cost, 0.015 * batch.stats.cost);
}

TEST(IncrementalFirstPlan, JointGoalIsTheBatchPlan) { expect_carried(rr_joint_goal()); }

TEST(IncrementalFirstPlan, PoseGoalIsTheBatchPlan) { expect_carried(rr_pose_goal()); }

// Settled (the default), the first plan is the tree's own optimum when that validates and costs
// no more than the batch plan, else the batch plan; either way valid and next to the batch plan.
TEST(IncrementalFirstPlan, SettledPlanIsAtLeastAsGood) {
  for (const Problem& p : {rr_joint_goal(), rr_pose_goal()}) {
    const Plan batch = BatchPlanner().plan(p);
    ASSERT_TRUE(batch.success()) << failures(batch);
    IncrementalPlanner planner;
    ASSERT_TRUE(planner.options().settle_first_plan);
    const Plan first = planner.plan(p);
    ASSERT_TRUE(first.success()) << failures(first);
    EXPECT_EQ(first.stats.method, batch.stats.method);
    EXPECT_LE(first.stats.cost, batch.stats.cost);
    EXPECT_LT(max_abs(first.q - batch.q), 2e-2);
    EXPECT_GE(first.stats.iterations, batch.stats.iterations);
  }
}

// A batch plan that does not validate is the answer as it is, with the tree at it: no settling
// updates and no second solve on the incremental graph (neither makes such a plan valid where
// the batch planner's own attempts failed).
TEST(IncrementalFirstPlan, AnInvalidBatchPlanIsAnsweredAsItIs) {
  IncrementalPlannerOptions options;
  const Problem p = testing::weak_elbow_acrobot(options.batch);
  const Plan batch = BatchPlanner(options.batch).plan(p);
  ASSERT_FALSE(batch.success());
  IncrementalPlanner planner(options);
  const Plan first = planner.plan(p);
  EXPECT_FALSE(first.success());
  EXPECT_EQ(first.stats.status, batch.stats.status);
  EXPECT_EQ(max_abs(first.q - batch.q), 0.0);
  EXPECT_EQ(first.stats.iterations, batch.stats.iterations) << "no second solve";
  EXPECT_EQ(planner.last_stats().updates, 0) << "not settled";
  EXPECT_TRUE(planner.has_plan());
}

// A settle is a polish of at most kSettleUpdates updates. On this task-1 goal the batch plan is
// valid but far from the tree's optimum, and the tree does not validate within them: the
// answer is the batch plan.
TEST(IncrementalFirstPlan, ASettleThatDoesNotValidateSoonLeavesTheBatchPlan) {
  const Scene scene = load_scene(kScenes + "iiwa_desk.yaml");
  GoalSampler sampler(scene.problem, bench::iiwa_goal_options(1));
  Problem p = scene.problem;
  p.goal.q = sampler.sample(9)[8];
  const Plan batch = BatchPlanner().plan(p);
  ASSERT_TRUE(batch.success()) << failures(batch);
  IncrementalPlanner planner;
  const Plan first = planner.plan(p);
  ASSERT_TRUE(first.success()) << failures(first);
  EXPECT_EQ(planner.last_stats().updates, kSettleUpdates) << "the settle used its budget";
  EXPECT_EQ(max_abs(first.q - batch.q), 0.0);
  EXPECT_EQ(first.stats.cost, batch.stats.cost);
  EXPECT_EQ(max_abs(planner.current_plan().q - batch.q), 0.0);
}

// The carried graph replans like one built from scratch: a goal change around the ball.
TEST(IncrementalFirstPlan, PoseGoalChangeReplansIncrementally) {
  const Problem p = rr_pose_goal();
  IncrementalPlanner planner;
  ASSERT_TRUE(planner.plan(p).success());
  const Plan re = planner.set_goal(tip_goal(p, Eigen::Vector2d(1.0, 0.9)));
  ASSERT_TRUE(re.success()) << failures(re);
  EXPECT_EQ(re.stats.method, "incremental");
  EXPECT_LT(re.validation.goal_error, 1e-3);
}

// The carried μ: a tenth of the batch's, within [floor, 1e4]; a valid plan held by large
// constraint forces gets at least ten times its largest force, up to the cap.
TEST(IncrementalFirstPlan, LargeForcesStiffenTheCarriedPenalty) {
  EXPECT_EQ(carried_penalty(1e7, 0, true, 100, 1e7), 1e4);
  EXPECT_EQ(carried_penalty(1e3, 0, true, 100, 1e7), 100);
  EXPECT_EQ(carried_penalty(1e5, 50, true, 100, 1e7), 1e4);
  EXPECT_DOUBLE_EQ(carried_penalty(1e5, 8.9e3, true, 100, 1e7), 8.9e4);
  EXPECT_EQ(carried_penalty(1e5, 8.9e3, false, 100, 1e7), 1e4) << "an invalid plan's forces";
  EXPECT_EQ(carried_penalty(1e5, 1e9, true, 100, 1e7), 1e7);
}

// The DFG formulation's graph (V, V̇, F, τ variables) is carried into the tree like the
// condensed one, and replans incrementally.
TEST(IncrementalFirstPlan, DfgFormulationIsCarried) {
  const Problem p = rr_joint_goal();
  IncrementalPlannerOptions options;
  options.batch.formulation = Formulation::kDynamicFactorGraph;
  IncrementalPlanner planner(options);
  const Plan first = planner.plan(p);
  ASSERT_TRUE(first.success()) << failures(first);
  ASSERT_TRUE(planner.has_plan());
  Goal g;
  g.q = Eigen::Vector2d(1.1, 0.2);
  const Plan re = planner.set_goal(g);
  EXPECT_TRUE(re.success()) << failures(re);
  EXPECT_EQ(re.stats.method, "incremental");
  EXPECT_GT(planner.last_stats().factors_added, 0);
  // The plan's torques are the DFG's own variables (RNEA of the trajectory has no residual).
  EXPECT_GT(re.validation.max_dynamics_residual, 0.0);
}

}  // namespace
}  // namespace kinograph::planning

// End-to-end batch plans of the planner's options: an end-effector pose goal, a task constraint
// that keeps the carried block's orientation, warm starts (W), a moving obstacle, and the
// minimum-torque objective.
#include <gtest/gtest.h>

#include <cmath>

#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/factors/pose_error.h"
#include "kinograph/planning/validate.h"
#include "tests/planning/test_problems.h"

namespace kinograph::planning {
namespace {

Eigen::Isometry3d pose_of(const Problem& p, const std::string& frame, const Eigen::VectorXd& q) {
  dynamics::Data data(*p.model);
  dynamics::forward_kinematics(*p.model, data, q);
  return dynamics::frame_pose(*p.model, data, p.model->frame_index(frame));
}

// Largest rotation (rad) of `frame` away from `target` over the plan's states.
double max_rotation_error(const Problem& p, const Plan& plan, const std::string& frame,
                          const Eigen::Isometry3d& target) {
  double worst = 0;
  for (int k = 0; k < plan.q.rows(); ++k) {
    const PoseError e = pose_error(pose_of(p, frame, plan.q.row(k).transpose()), target);
    worst = std::max(worst, e.rotation);
  }
  return worst;
}

void expect_valid(const Plan& plan) {
  for (const auto& f : plan.validation.failures) ADD_FAILURE() << f;
  EXPECT_TRUE(plan.success()) << plan.stats.status << ": " << plan.stats.reason;
}

TEST(EndToEnd, PoseGoalReachesThePose) {
  Problem p = testing::iiwa_swing(20);
  const Eigen::VectorXd q_target = p.goal.q;
  p.goal = Goal{};
  p.goal.kind = Goal::Kind::kPose;
  p.goal.frame = "payload";
  p.goal.pose = pose_of(p, "payload", q_target);
  const Plan plan = BatchPlanner().plan(p);
  expect_valid(plan);
  const PoseError e =
      pose_error(pose_of(p, "payload", plan.q.bottomRows(1).transpose()), p.goal.pose);
  EXPECT_LT(e.position, 1e-3);
  EXPECT_LT(e.rotation, 1e-3);
  EXPECT_LT(plan.qd.bottomRows(1).cwiseAbs().maxCoeff(), 1e-6);  // at rest
}

TEST(EndToEnd, PositionOnlyPoseGoal) {
  Problem p = testing::iiwa_swing(20);
  const Eigen::VectorXd q_target = p.goal.q;
  p.goal = Goal{};
  p.goal.kind = Goal::Kind::kPose;
  p.goal.frame = "payload";
  p.goal.position_only = true;
  // A position above the swung-to pose, any orientation.
  p.goal.pose = pose_of(p, "payload", q_target);
  p.goal.pose.translation().z() += 0.1;
  const Plan plan = BatchPlanner().plan(p);
  expect_valid(plan);
  const Eigen::Vector3d reached =
      pose_of(p, "payload", plan.q.bottomRows(1).transpose()).translation();
  EXPECT_LT((reached - p.goal.pose.translation()).norm(), 1e-3);
}

// Moves the block 25 cm sideways and 10 cm up with its orientation kept along the way.
Problem level_block_move() {
  Problem p = testing::iiwa_swing(20);
  const Eigen::Isometry3d start = pose_of(p, "payload", p.start_q);
  p.goal = Goal{};
  p.goal.kind = Goal::Kind::kPose;
  p.goal.frame = "payload";
  p.goal.pose = start;
  p.goal.pose.translation() += Eigen::Vector3d(0.15, 0.25, 0.1);
  return p;
}

TEST(EndToEnd, TaskConstraintKeepsTheBlockLevel) {
  Problem p = level_block_move();
  const Eigen::Isometry3d start = pose_of(p, "payload", p.start_q);
  const Plan free_plan = BatchPlanner().plan(p);
  expect_valid(free_plan);
  TaskConstraint keep;
  keep.frame = "payload";
  keep.orientation_only = true;
  keep.target = start;
  keep.tolerance = 0.01;
  p.task_constraints.push_back(keep);
  const Plan plan = BatchPlanner().plan(p);
  expect_valid(plan);
  const double err = max_rotation_error(p, plan, "payload", start);
  EXPECT_LT(err, keep.tolerance);
  EXPECT_LE(plan.validation.max_task_error, keep.tolerance);
  // The unconstrained plan tilts the block on the way: the constraint did something.
  EXPECT_GT(max_rotation_error(p, free_plan, "payload", start), 2 * err);
}

TEST(EndToEnd, WarmStartFromItsOwnPlanIsCheap) {
  const Problem p = testing::rr_reach();
  const BatchPlanner planner;
  const Plan cold = planner.plan(p);
  expect_valid(cold);
  const Plan warm = planner.plan(p, &cold);
  expect_valid(warm);
  EXPECT_EQ(cold.stats.method, "batch-L");
  EXPECT_EQ(warm.stats.method, "batch-W");
  EXPECT_LT(warm.stats.iterations, cold.stats.iterations);
  EXPECT_LT((warm.q - cold.q).cwiseAbs().maxCoeff(), 0.05);
}

TEST(EndToEnd, WarmStartAfterTheGoalMoves) {
  Problem p = testing::rr_reach();
  const BatchPlanner planner;
  const Plan first = planner.plan(p);
  expect_valid(first);
  p.goal.q = Eigen::Vector2d(1.1, 0.1);
  const Plan warm = planner.plan(p, &first);
  expect_valid(warm);
  EXPECT_NEAR(warm.q(p.steps, 0), 1.1, 1e-6);
  EXPECT_NEAR(warm.q(p.steps, 1), 0.1, 1e-6);
  // A warm start from a plan of another robot is bad input, reported, not thrown.
  Problem other = testing::iiwa_swing(10);
  const Plan bad = planner.plan(other, &first);
  EXPECT_EQ(bad.stats.status, PlanStatus::kInvalidProblem);
  EXPECT_FALSE(bad.success());
}

TEST(EndToEnd, MovingObstacleIsAvoidedWhenItArrives) {
  // The RR arm swings over the top; a ball arrives at the top halfway through the motion.
  Problem p = testing::rr_reach();
  collision::Obstacle& ball = p.obstacles[0];
  const Eigen::Isometry3d top = ball.pose;
  Eigen::Isometry3d away = top;
  away.translation().x() += 3.0;
  ball.trajectory = collision::PoseTrajectory({0.0, 1.2, 3.0}, {away, top, top});
  const Plan plan = BatchPlanner().plan(p);
  expect_valid(plan);
  EXPECT_GE(plan.validation.min_clearance, 0.0);
  // The same ball, parked away for the whole motion: the arm need not bend.
  Problem parked = testing::rr_reach();
  parked.obstacles[0].pose = away;
  const Plan straight = BatchPlanner().plan(parked);
  expect_valid(straight);
  EXPECT_LT(straight.q.col(1).cwiseAbs().maxCoeff(), 1e-3);
  // That motion would meet the arriving ball; the plan gets out of its way (by bending or by
  // timing: either is a valid answer).
  EXPECT_LT(validate(p, straight).min_clearance, 0.0);
  EXPECT_GT((plan.q - straight.q).cwiseAbs().maxCoeff(), 0.05);
}

TEST(EndToEnd, MinimumTorqueLowersTheTorque) {
  Problem p = testing::iiwa_swing(20);
  const Plan plain = BatchPlanner().plan(p);
  p.objectives.min_torque = 1e-2;
  const Plan low = BatchPlanner().plan(p);
  expect_valid(plain);
  expect_valid(low);
  // Both the objective's own measure (Σ τ²) and the paper's total torque (Σ |τ|) drop.
  EXPECT_LT(low.tau.squaredNorm(), 0.95 * plain.tau.squaredNorm());
  EXPECT_LT(low.tau.cwiseAbs().sum(), plain.tau.cwiseAbs().sum());
}

}  // namespace
}  // namespace kinograph::planning

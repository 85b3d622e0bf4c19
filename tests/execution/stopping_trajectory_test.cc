// Stopping trajectories: the piecewise-linear-acceleration plan is exactly the interpolant of
// its knots (closed form and validate's consistency figures); a stop starts at the state it
// stops from (q, q̇ and q̈), ends at rest, validates for the scene, is the shortest duration
// tried that does, and a state no stop within the limits can bring to rest is reported.
#include "kinograph/execution/stopping_trajectory.h"

#include <gtest/gtest.h>

#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/trajectory_sampler.h"
#include "kinograph/planning/validate.h"

namespace kinograph::execution {
namespace {

planning::Scene desk() {
  return planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml");
}

TEST(LinearAccelerationPlan, ConstantAccelerationIsTheParabola) {
  const planning::Scene scene = desk();
  const dynamics::Model& model = *scene.problem.model;
  const Eigen::VectorXd q0 = scene.problem.start_q, qd0 = Eigen::VectorXd::Constant(7, 0.1);
  const Eigen::VectorXd a = Eigen::VectorXd::Constant(7, -0.3);
  const planning::Plan plan = linear_acceleration_plan(model, q0, qd0, {0, 0.4}, {a, a}, 4);
  ASSERT_EQ(plan.t.size(), 5u);
  for (int k = 0; k < 5; ++k) {
    const double t = plan.t[k];
    EXPECT_NEAR(t, 0.1 * k, 1e-15);
    EXPECT_LE((plan.q.row(k).transpose() - (q0 + qd0 * t + a * t * t / 2)).norm(), 1e-15);
    EXPECT_LE((plan.qd.row(k).transpose() - (qd0 + a * t)).norm(), 1e-15);
  }
}

TEST(LinearAccelerationPlan, IsTheInterpolantOfItsKnots) {
  const planning::Scene scene = desk();
  const dynamics::Model& model = *scene.problem.model;
  Eigen::VectorXd a0(7), a1(7), a2(7);
  a0 << 0.5, -0.2, 0.1, 0.3, -0.4, 0.2, 0.1;
  a1 << -0.6, 0.3, 0.2, -0.1, 0.5, -0.3, 0.0;
  a2.setZero();
  const planning::Plan plan = linear_acceleration_plan(
      model, scene.problem.start_q, Eigen::VectorXd::Zero(7), {0, 0.3, 0.7}, {a0, a1, a2}, 3);
  planning::TrajectorySampler sampler(model, plan);
  // Where each interval's interpolant arrives is the next knot, to rounding.
  for (int k = 0; k < sampler.intervals(); ++k) {
    const planning::InterpolantPoint end = sampler.interval_end(k);
    EXPECT_LE((end.q - plan.q.row(k + 1).transpose()).cwiseAbs().maxCoeff(), 1e-14) << k;
    EXPECT_LE((end.qd - plan.qd.row(k + 1).transpose()).cwiseAbs().maxCoeff(), 1e-14) << k;
    EXPECT_LE((end.qdd - plan.qdd.row(k + 1).transpose()).cwiseAbs().maxCoeff(), 1e-12) << k;
  }
  // Its torques are the inverse dynamics, as validate checks.
  planning::Problem problem = scene.problem;
  problem.obstacles.clear();
  problem.steps = 6;
  problem.horizon = 0.7;
  problem.goal.q = plan.q.bottomRows(1).transpose();
  const planning::Validation v = planning::validate(problem, plan);
  EXPECT_LE(v.max_dynamics_residual, 1e-9);
  EXPECT_LE(v.max_position_consistency, 1e-14);
}

TEST(LinearAccelerationPlan, RefusesMismatchedInput) {
  const planning::Scene scene = desk();
  const dynamics::Model& model = *scene.problem.model;
  const Eigen::VectorXd z = Eigen::VectorXd::Zero(7), q = scene.problem.start_q;
  EXPECT_THROW(linear_acceleration_plan(model, q, z, {0, 1}, {z}, 1), std::invalid_argument);
  EXPECT_THROW(linear_acceleration_plan(model, q, z, {0, 0}, {z, z}, 1), std::invalid_argument);
  EXPECT_THROW(linear_acceleration_plan(model, q, Eigen::VectorXd::Zero(6), {0, 1}, {z, z}, 1),
               std::invalid_argument);
  EXPECT_THROW(linear_acceleration_plan(model, q, z, {0, 1}, {z, z}, 0), std::invalid_argument);
}

TEST(StoppingTrajectory, StartsWhereTheRobotIsAndEndsAtRest) {
  const planning::Scene scene = desk();
  const dynamics::Model& model = *scene.problem.model;
  Eigen::VectorXd qd(7), qdd(7);
  qd << 0.4, -0.5, 0.3, 0.6, -0.2, 0.5, 0.3;
  qdd << 1.0, -0.5, 0.2, 0.0, 0.3, -1.0, 0.5;
  const StoppingTrajectory stop =
      stopping_trajectory(scene.problem, scene.problem.start_q, qd, qdd);
  ASSERT_TRUE(stop.valid) << stop.reason;
  const planning::Plan& p = stop.plan;
  EXPECT_EQ(p.q.row(0).transpose(), scene.problem.start_q);
  EXPECT_EQ(p.qd.row(0).transpose(), qd);
  EXPECT_EQ(p.qdd.row(0).transpose(), qdd);
  const Eigen::Index last = p.q.rows() - 1;
  EXPECT_LE(p.qd.row(last).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(p.qdd.row(last).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_NEAR(p.t.back(), stop.duration_s, 1e-12);
  // Validate agrees, with the scene's obstacles, and the sampler reads knot 0 as the state.
  planning::Problem problem = scene.problem;
  problem.start_qd = qd;
  problem.horizon = stop.duration_s;
  problem.steps = static_cast<int>(last);
  problem.goal.q = p.q.row(last).transpose();
  EXPECT_TRUE(planning::validate(problem, p).valid);
  planning::TrajectorySampler sampler(model, p);
  EXPECT_LE((sampler.at(0).qdd - qdd).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(StoppingTrajectory, TakesTheShortestDurationThatValidates) {
  planning::Scene scene = desk();
  // With a 3 rad/s² acceleration limit on every joint, stopping from 0.5 rad/s takes longer
  // than the shortest stops (a 0.2 s stop peaks at 5 rad/s²).
  auto model = std::make_shared<dynamics::Model>(*scene.problem.model);
  for (auto& body : model->bodies) body.limits.acceleration = 3.0;
  scene.problem.model = model;
  const Eigen::VectorXd qd = Eigen::VectorXd::Constant(7, 0.5);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(7);
  const StoppingTrajectory stop =
      stopping_trajectory(scene.problem, scene.problem.start_q, qd, zero);
  ASSERT_TRUE(stop.valid) << stop.reason;
  ASSERT_GT(stop.duration_s, kShortestStopS);
  // Half as long does not validate: the reason is the validator's.
  const double T = stop.duration_s / 2;
  const planning::Plan shorter = linear_acceleration_plan(
      *scene.problem.model, scene.problem.start_q, qd, {0, T / 2, T}, {zero, -2 * qd / T, zero}, 5);
  planning::Problem problem = scene.problem;
  problem.start_qd = qd;
  problem.horizon = T;
  problem.steps = 10;
  problem.goal.q = shorter.q.bottomRows(1).transpose();
  problem.task_constraints.clear();
  const planning::Validation v = planning::validate(problem, shorter);
  EXPECT_FALSE(v.valid);
  EXPECT_GT(v.max_qdd_violation, 0.0);
}

TEST(StoppingTrajectory, ReportsAStateNoStopCanBringToRest) {
  const planning::Scene scene = desk();
  // Joint 1 at 3 rad/s is already beyond its 1.48 rad/s limit: no stop is within the limits.
  Eigen::VectorXd qd = Eigen::VectorXd::Zero(7);
  qd[0] = 3.0;
  const StoppingTrajectory stop =
      stopping_trajectory(scene.problem, scene.problem.start_q, qd, Eigen::VectorXd::Zero(7));
  EXPECT_FALSE(stop.valid);
  EXPECT_NE(stop.reason.find("iiwa_joint_1"), std::string::npos) << stop.reason;
  EXPECT_NE(stop.reason.find("no stop of"), std::string::npos) << stop.reason;
}

}  // namespace
}  // namespace kinograph::execution

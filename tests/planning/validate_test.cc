// validate() passes a consistent plan and catches each kind of violation on doctored copies.
#include "kinograph/planning/validate.h"

#include <gtest/gtest.h>

#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/kinematics.h"

#include "tests/planning/test_problems.h"

namespace kinograph::planning {
namespace {

// The RR arm holding still at q* for 1 s: consistent, within limits, τ = gravity torque.
using Fixture = testing::StillRr;

bool mentions(const Validation& v, const std::string& what) {
  for (const auto& f : v.failures) {
    if (f.find(what) != std::string::npos) return true;
  }
  return false;
}

TEST(Validate, AcceptsAConsistentPlan) {
  Fixture f;
  const Validation v = validate(f.problem, f.plan);
  EXPECT_TRUE(v.valid) << (v.failures.empty() ? "" : v.failures.front());
  EXPECT_LT(v.max_dynamics_residual, 1e-9);
  EXPECT_EQ(v.goal_error, 0);
}

bool mentions_all(const Validation& v, std::initializer_list<std::string> parts) {
  for (const auto& f : v.failures) {
    bool all = true;
    for (const std::string& p : parts) all = all && f.find(p) != std::string::npos;
    if (all) return true;
  }
  return false;
}

std::string all_failures(const Validation& v) {
  std::string s;
  for (const auto& f : v.failures) s += " | " + f;
  return s;
}

// Start, goal and task failures say which joint or frame misses, by how much, and when.
TEST(Validate, StartGoalAndTaskFailuresNameJointFrameAndTime) {
  {
    Fixture f;
    f.problem.goal.q[1] += 0.2;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions_all(v, {"goal error", "joint 2 (joint2) ends at -0.3 rad, its goal is -0.1",
                                 "at t = 1 s"}))
        << all_failures(v);
  }
  {
    Fixture f;
    f.problem.start_q[0] += 0.05;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions_all(v, {"start state error", "joint 1 (joint1) position 0.5 rad instead of "
                                 "0.55", "at t = 0"}))
        << all_failures(v);
  }
  {
    Fixture f;
    f.plan.qd(10, 1) = 0.05;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions_all(v, {"final velocity", "joint 2 (joint2) velocity 0.05 rad/s",
                                 "at t = 1 s"}))
        << all_failures(v);
  }
  {
    Fixture f;
    dynamics::Data d(*f.problem.model);
    dynamics::forward_kinematics(*f.problem.model, d, f.problem.goal.q);
    TaskConstraint task;
    task.frame = "ee";
    task.target = dynamics::frame_pose(*f.problem.model, d, f.problem.model->frame_index("ee"));
    task.tolerance = 0.05;
    f.problem.task_constraints.push_back(task);
    f.plan.q(7, 0) += 0.3;  // the ee tilts by 0.3 rad at step 7 only (both joints turn about y)
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions_all(v, {"task constraint on 'ee'", "at t = 0.7 s"})) << all_failures(v);
  }
}

TEST(Validate, CatchesEachViolation) {
  {
    Fixture f;
    f.plan.tau(4, 1) += 0.1;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_FALSE(v.valid);
    EXPECT_TRUE(mentions(v, "dynamics"));
    EXPECT_NEAR(v.max_dynamics_residual, 0.1, 1e-9);
  }
  {
    Fixture f;
    f.plan.q(5, 0) += 0.1;  // a jump in q alone breaks the position trapezoid
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions(v, "position consistency"));
  }
  {
    Fixture f;
    f.plan.qd(5, 1) = 0.5;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions(v, "consistency"));
  }
  {
    Fixture f;
    f.problem.goal.q[1] += 0.2;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions(v, "goal"));
    EXPECT_NEAR(v.goal_error, 0.2, 1e-12);
  }
  {
    Fixture f;  // effort limit of joint 1 is 60 N·m
    f.plan.tau(3, 0) = 70;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions(v, "effort"));
    EXPECT_NEAR(v.max_tau_violation, 10, 1e-9);
  }
  {
    Fixture f;  // velocity limit 3 rad/s
    f.plan.qd(2, 0) = 3.5;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions(v, "velocity limit"));
    EXPECT_NEAR(v.max_qd_violation, 0.5, 1e-12);
  }
  {
    Fixture f;  // position limit ±π
    f.plan.q.col(0).setConstant(3.5);
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions(v, "position limit"));
  }
  {
    Fixture f;
    auto m = std::make_shared<dynamics::Model>(*f.problem.model);
    m->bodies[0].actuated = false;
    f.problem.model = m;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions(v, "unactuated"));
  }
  {
    Fixture f;  // a ball on the arm
    collision::Obstacle ball;
    ball.shape = collision::Shape::sphere(0.1);
    ball.pose.translation() = Eigen::Vector3d(std::sin(0.5) * 0.5, 0, std::cos(0.5) * 0.5);
    f.problem.obstacles.push_back(ball);
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions(v, "collision"));
    EXPECT_LT(v.min_clearance, 0);
  }
  {
    Fixture f;
    f.plan.qdd(1, 1) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_FALSE(validate(f.problem, f.plan).valid);
    f.plan.q.resize(3, 2);
    EXPECT_FALSE(validate(f.problem, f.plan).valid);
  }
}

}  // namespace
}  // namespace kinograph::planning

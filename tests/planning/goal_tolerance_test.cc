// A goal's own tolerances replace the validator's default goal threshold, per joint or per
// position and orientation, and bad tolerances are refused by the problem check.
#include <gtest/gtest.h>

#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/problem_check.h"
#include "kinograph/planning/validate.h"
#include "tests/planning/test_problems.h"

namespace kinograph::planning {
namespace {

using Fixture = testing::StillRr;

bool mentions(const Validation& v, const std::string& what) {
  for (const auto& f : v.failures) {
    if (f.find(what) != std::string::npos) return true;
  }
  return false;
}

// The plan ends 0.005 rad from joint 2's goal: valid at the default 0.01, invalid at 0.001,
// and a tolerance on the other joint does not loosen or tighten joint 2's.
TEST(GoalTolerance, AJointToleranceIsThatJointsThreshold) {
  Fixture f;
  f.problem.goal.q[1] += 0.005;
  EXPECT_TRUE(validate(f.problem, f.plan).valid);
  f.problem.goal.joint_tolerance = Eigen::Vector2d(1e-4, 0);
  EXPECT_TRUE(validate(f.problem, f.plan).valid);
  f.problem.goal.joint_tolerance = Eigen::Vector2d(0, 1e-3);
  const Validation tight = validate(f.problem, f.plan);
  EXPECT_FALSE(tight.valid);
  EXPECT_TRUE(mentions(tight, "goal error 0.005 exceeds 0.001")) << tight.failures.front();
  EXPECT_TRUE(mentions(tight, "joint 2 (joint2)")) << tight.failures.front();
  EXPECT_NEAR(tight.goal_error, 0.005, 1e-12);
}

// 0.05 rad off: invalid by default, valid with a 0.06 rad tolerance on that joint.
TEST(GoalTolerance, ALooseJointToleranceAcceptsAFartherEnd) {
  Fixture f;
  f.problem.goal.q[0] -= 0.05;
  EXPECT_FALSE(validate(f.problem, f.plan).valid);
  f.problem.goal.joint_tolerance = Eigen::Vector2d(0.06, 0);
  EXPECT_TRUE(validate(f.problem, f.plan).valid);
}

// A pose goal 0.03 m from where the tip ends: the position tolerance decides.
TEST(GoalTolerance, APositionToleranceIsThePoseGoalsThreshold) {
  Fixture f;
  f.problem.goal = testing::tip_goal(f.problem, f.problem.start_q);
  f.problem.goal.pose.translation().x() += 0.03;
  const Validation by_default = validate(f.problem, f.plan);
  EXPECT_FALSE(by_default.valid);
  EXPECT_TRUE(mentions(by_default, "m from its goal position"));
  f.problem.goal.position_tolerance = 0.04;
  EXPECT_TRUE(validate(f.problem, f.plan).valid);
  f.problem.goal.position_tolerance = 0.02;
  EXPECT_FALSE(validate(f.problem, f.plan).valid);
}

// An orientation off by 0.1 rad about the arm's joint axis is judged by the orientation
// tolerance, unless the goal is position only.
TEST(GoalTolerance, AnOrientationToleranceIsThePoseGoalsRotationThreshold) {
  Fixture f;
  f.problem.goal = testing::tip_goal(f.problem, f.problem.start_q);
  f.problem.goal.position_only = false;
  f.problem.goal.pose.rotate(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()));
  const Validation by_default = validate(f.problem, f.plan);
  EXPECT_FALSE(by_default.valid);
  EXPECT_TRUE(mentions(by_default, "rad from its goal orientation"));
  f.problem.goal.orientation_tolerance = 0.11;
  EXPECT_TRUE(validate(f.problem, f.plan).valid);
}

TEST(GoalTolerance, BadTolerancesAreRefusedByTheProblemCheck) {
  Fixture f;
  EXPECT_EQ(check_problem(f.problem), "");
  f.problem.goal.joint_tolerance = Eigen::Vector3d(0.1, 0.1, 0.1);
  EXPECT_EQ(check_problem(f.problem), "joint goal tolerance has the wrong size");
  f.problem.goal.joint_tolerance = Eigen::Vector2d(0.1, -1);
  EXPECT_EQ(check_problem(f.problem), "the goal tolerance of joint 2 (joint2) must be a number >= 0");
  f.problem.goal.joint_tolerance.resize(0);
  f.problem.goal.position_tolerance = std::nan("");
  EXPECT_NE(check_problem(f.problem).find("tolerances must be numbers >= 0"), std::string::npos);
}

}  // namespace
}  // namespace kinograph::planning

// Robots checked together on a common clock: closed forms with sliding spheres (the closest
// approach between the knots, plans starting at different times, each robot held at its ends),
// the pair named, and bad input refused with the robot's name.
#include "kinograph/fleet/joint_clearance.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/fleet/slider.h"

namespace kinograph::fleet {
namespace {

using testing::constant_velocity;
using testing::kSphereRadius;
using testing::slider;

TEST(JointClearance, FindsTheClosestApproachBetweenTheKnots) {
  // 'a' crosses from x = −1 to x = 1 in one interval of 1 s; 'b' stands 0.25 m to the side at
  // x = 0. At the knots they are 1.03 m apart; at t = 0.5 s only 0.25 − 2r.
  const std::vector<RobotPlan> robots = {
      {"a", slider(Eigen::Vector3d(0, 0, 0)), constant_velocity(-1.0, 2.0, 1.0, 1), 0.0},
      {"b", slider(Eigen::Vector3d(0, 0.25, 0)), constant_velocity(0.0, 0.0, 1.0, 1), 0.0}};
  const JointClearance c = joint_clearance(robots);
  EXPECT_NEAR(c.min_distance, 0.25 - 2 * kSphereRadius, 1e-6);
  EXPECT_NEAR(c.t, 0.5, 1e-12);
  EXPECT_EQ(c.robot_a, "a");
  EXPECT_EQ(c.link_a, "ball");
  EXPECT_EQ(c.robot_b, "b");
  EXPECT_TRUE(c.clear());
  EXPECT_FALSE(c.clear(0.1));
  EXPECT_EQ(c.samples, 11);
}

TEST(JointClearance, LeavesOutWhatLiesBeforeFromAndFromToOn) {
  // As above, checked from t = 0.75 s on: 'a' has passed x = 0 and is closest at 0.75 s, at
  // x = 0.5: sqrt(0.5² + 0.25²) − 2r. Checked before t = 0.25 s only: closest at the last time
  // checked, 0.2 s, x = −0.6.
  const std::vector<RobotPlan> robots = {
      {"a", slider(Eigen::Vector3d(0, 0, 0)), constant_velocity(-1.0, 2.0, 1.0, 1), 0.0},
      {"b", slider(Eigen::Vector3d(0, 0.25, 0)), constant_velocity(0.0, 0.0, 1.0, 1), 0.0}};
  const JointClearance late = joint_clearance(robots, {.from = 0.75});
  EXPECT_NEAR(late.min_distance, std::sqrt(0.5 * 0.5 + 0.25 * 0.25) - 2 * kSphereRadius, 1e-6);
  EXPECT_NEAR(late.t, 0.75, 1e-12);
  const JointClearance early = joint_clearance(robots, {.to = 0.25});
  EXPECT_NEAR(early.min_distance, std::sqrt(0.6 * 0.6 + 0.25 * 0.25) - 2 * kSphereRadius, 1e-6);
  EXPECT_NEAR(early.t, 0.2, 1e-12);
  EXPECT_EQ(early.samples, 3);
}

// 'a' moves +0.5 m/s from x = 0; at t = 1 s a second plan takes over where the first has it
// (x = 0.5) and turns it back. 'b', 0.15 m to the side, sweeps from x = 0.5 to 2.5 in the first
// second. The history keeps 0.5 m apart along x, closest at t = 0 (a at 0, b at 0.5); the second
// plan alone, a standing at its first knot before it starts, would put a under b at t = 0.
TEST(HistoryClearance, MovesEachRobotAlongThePlanInForce) {
  const auto a = slider(Eigen::Vector3d(0, 0, 0));
  const auto b = slider(Eigen::Vector3d(0, 0.15, 0));
  const planning::Plan out = constant_velocity(0.0, 0.5, 2.0, 10);
  const planning::Plan back = constant_velocity(0.5, -0.5, 1.0, 5);
  const planning::Plan sweep = constant_velocity(0.5, 2.0, 1.0, 5);
  const std::vector<RobotHistory> history = {{"a", a, {{out, 0.0}, {back, 1.0}}},
                                             {"b", b, {{sweep, 0.0}}}};
  const double expected = std::sqrt(0.5 * 0.5 + 0.15 * 0.15) - 2 * kSphereRadius;
  HistoryMemo memo;
  const JointClearance c = history_clearance(history, {}, &memo);
  EXPECT_NEAR(c.min_distance, expected, 1e-6);
  EXPECT_NEAR(c.t, 0.0, 1e-12);
  EXPECT_EQ(c.robot_a, "a");
  const JointClearance latest =
      joint_clearance({{"a", a, back, 1.0}, {"b", b, sweep, 0.0}}, {.to = 1.0});
  EXPECT_LT(latest.min_distance, 0.0);
  // Checked again with the same plans: every window known, the same answer.
  const std::size_t windows = memo.size();
  EXPECT_EQ(windows, 3u);  // before 0 s, 0–1 s, from 1 s on
  EXPECT_NEAR(history_clearance(history, {}, &memo).min_distance, expected, 1e-12);
  EXPECT_EQ(memo.size(), windows);
  EXPECT_THROW(history_clearance({{"a", a, {}}}), std::invalid_argument);
}

TEST(JointClearance, PutsEveryPlanOnTheCommonClockAndHoldsItsEnds) {
  // 'a' at x = 0 moves +0.3 m/s for 1 s, then stands at 0.3; 'b' at x = 1 stands still until
  // t = 0.5 s, then moves −0.3 m/s until 1.5 s. Closest at t = 1.5: 1 − 0.3 − 0.3 − 2r.
  const std::vector<RobotPlan> robots = {
      {"a", slider(Eigen::Vector3d(0, 0, 0)), constant_velocity(0.0, 0.3, 1.0, 5), 0.0},
      {"b", slider(Eigen::Vector3d(1, 0, 0)), constant_velocity(0.0, -0.3, 1.0, 5), 0.5}};
  const JointClearance c = joint_clearance(robots);
  EXPECT_NEAR(c.min_distance, 0.4 - 2 * kSphereRadius, 1e-6);
  EXPECT_NEAR(c.t, 1.5, 1e-9);
}

TEST(JointClearance, ReportsAnOverlapWithTheDepth) {
  // Head-on at 0.45 m/s each from 1 m apart: at t = 1 s the centres are 0.1 m apart, the spheres
  // overlap by 2r − 0.1. The third robot stands far away and is never the closest pair.
  const std::vector<RobotPlan> robots = {
      {"left", slider(Eigen::Vector3d(0, 0, 0)), constant_velocity(0.0, 0.45, 1.0, 4), 0.0},
      {"far", slider(Eigen::Vector3d(0, 5, 0)), constant_velocity(0.0, 0.0, 1.0, 4), 0.0},
      {"right", slider(Eigen::Vector3d(1, 0, 0)), constant_velocity(0.0, -0.45, 1.0, 4), 0.0}};
  const JointClearance c = joint_clearance(robots);
  EXPECT_NEAR(c.min_distance, 0.1 - 2 * kSphereRadius, 1e-6);
  EXPECT_NEAR(c.t, 1.0, 1e-9);
  EXPECT_FALSE(c.clear());
  EXPECT_EQ(c.robot_a, "left");
  EXPECT_EQ(c.robot_b, "right");
  EXPECT_NE(describe(c).find("overlap by 0.1 m"), std::string::npos) << describe(c);
  EXPECT_NE(describe(c).find("'left' (link 'ball') and 'right'"), std::string::npos);
}

TEST(JointClearance, RefusesBadInputNamingTheRobot) {
  planning::Plan bad = constant_velocity(0.0, 0.0, 1.0, 2);
  bad.t[1] = bad.t[0];
  std::vector<RobotPlan> robots = {
      {"a", slider(Eigen::Vector3d::Zero()), constant_velocity(0.0, 0.0, 1.0, 2), 0.0},
      {"b", slider(Eigen::Vector3d(1, 0, 0)), bad, 0.0}};
  try {
    joint_clearance(robots);
    FAIL() << "a plan whose times do not increase was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("robot 'b'"), std::string::npos) << e.what();
  }
  robots[1] = robots[0];
  EXPECT_THROW(joint_clearance(robots), std::invalid_argument);  // two robots named 'a'
  robots.pop_back();
  EXPECT_THROW(joint_clearance(robots, {.samples_per_interval = 0}), std::invalid_argument);
}

}  // namespace
}  // namespace kinograph::fleet

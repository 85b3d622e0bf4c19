// Drake's messages in and out: an iiwa status becomes the measured state in the URDF's joint
// order (or is refused naming the field), and a plan becomes a Drake robot plan whose knots
// carry the plan's times within it, its joint names and its positions.
#include "kinograph/lcm/drake_convert.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace kinograph::messages {
namespace {

const dynamics::Model& iiwa() {
  static const dynamics::Model model = dynamics::Model::from_urdf_file(
      std::string(KINOGRAPH_SOURCE_DIR) + "/robots/iiwa14/iiwa14.urdf");
  return model;
}

drake::lcmt_iiwa_status status(int n) {
  drake::lcmt_iiwa_status m;
  m.utime = 5'000'000;
  m.num_joints = n;
  for (auto* v : {&m.joint_position_measured, &m.joint_velocity_estimated,
                  &m.joint_position_commanded, &m.joint_position_ipo, &m.joint_torque_measured,
                  &m.joint_torque_commanded, &m.joint_torque_external}) {
    v->assign(n, 0.0);
  }
  for (int j = 0; j < n; ++j) {
    m.joint_position_measured[j] = 0.1 * (j + 1);
    m.joint_velocity_estimated[j] = -0.01 * (j + 1);
    m.joint_position_commanded[j] = 9.0;  // not the measurement: must not be read as q
  }
  return m;
}

TEST(IiwaStatus, IsTheMeasuredStateInJointOrder) {
  MeasuredState state;
  const Check c = state_from_iiwa_status(status(7), iiwa(), state);
  ASSERT_TRUE(c.ok) << c.reason;
  EXPECT_EQ(state.utime, 5'000'000);
  for (int j = 0; j < 7; ++j) {
    EXPECT_DOUBLE_EQ(state.q[j], 0.1 * (j + 1));
    EXPECT_DOUBLE_EQ(state.qd[j], -0.01 * (j + 1));
  }
}

TEST(IiwaStatus, AWrongJointCountIsRefusedNamingTheField) {
  MeasuredState state;
  const Check c = state_from_iiwa_status(status(6), iiwa(), state);
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.reason.find("lcmt_iiwa_status.num_joints is 6, robot iiwa14 has 7 joints"),
            std::string::npos)
      << c.reason;
}

TEST(IiwaStatus, ANonFiniteMeasurementIsRefused) {
  drake::lcmt_iiwa_status m = status(7);
  m.joint_velocity_estimated[3] = std::numeric_limits<double>::quiet_NaN();
  MeasuredState state;
  const Check c = state_from_iiwa_status(m, iiwa(), state);
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.reason.find("not finite"), std::string::npos) << c.reason;
}

plan_t three_knot_plan() {
  plan_t p{};
  p.plan_id = 4;
  p.status = plan_t::SUCCESS;
  p.clock = plan_t::CLOCK_ROBOT;
  p.start_utime = 5'000'000;
  p.num_joints = 2;
  p.joint_name = {"joint1", "joint2"};
  p.num_steps = 3;
  p.t = {0.0, 0.1, 0.2};
  p.q = {{0.0, 1.0}, {0.25, 0.75}, {0.5, 0.5}};
  return p;
}

TEST(RobotPlan, KnotsCarryTheirTimesWithinThePlanNamesAndPositions) {
  const drake::lcmt_robot_plan out = robot_plan_from_plan(three_knot_plan());
  EXPECT_EQ(out.utime, 5'000'000);
  ASSERT_EQ(out.num_states, 3);
  ASSERT_EQ(out.plan.size(), 3u);
  const int64_t times[] = {0, 100'000, 200'000};
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(out.plan[k].utime, times[k]);
    EXPECT_EQ(out.plan[k].num_joints, 2);
    EXPECT_EQ(out.plan[k].joint_name, (std::vector<std::string>{"joint1", "joint2"}));
    ASSERT_EQ(out.plan[k].joint_position.size(), 2u);
  }
  EXPECT_FLOAT_EQ(out.plan[1].joint_position[0], 0.25f);
  EXPECT_FLOAT_EQ(out.plan[2].joint_position[1], 0.5f);
}

TEST(RobotPlan, APlanWithoutTrajectoryIsRefused) {
  plan_t p = three_knot_plan();
  p.num_steps = 0;
  p.t.clear();
  p.q.clear();
  EXPECT_THROW(robot_plan_from_plan(p), std::invalid_argument);
}

}  // namespace
}  // namespace kinograph::messages

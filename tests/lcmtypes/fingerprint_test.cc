// The fingerprints of the LCM types against the value LCM's documented rule gives for the
// member layout each type must have (tests/lcmtypes/lcm_fingerprint.h, computed here, not by
// lcm-gen): Drake's three types as Drake publishes them, so that Drake's programs accept
// kinograph's messages and kinograph theirs; plan_v1_t as the first plan_t, so that old logs
// decode; and the current plan_t, whose fingerprint must differ from version 1's.
#include <gtest/gtest.h>

#include <cstdint>

#include "drake/lcmt_iiwa_status.hpp"
#include "drake/lcmt_robot_plan.hpp"
#include "drake/lcmt_robot_state.hpp"
#include "kinograph/joint_command_t.hpp"
#include "kinograph/plan_t.hpp"
#include "kinograph/plan_v1_t.hpp"
#include "kinograph/robot_state_t.hpp"
#include "tests/lcmtypes/lcm_fingerprint.h"

namespace kinograph::lcmtypes::testing {
namespace {

MemberSpec per_joint(const char* name, const char* type) {
  return member(name, type, {var("num_joints")});
}

// Drake's lcmt_robot_state: a plan knot (utime, int16 count, names, float positions).
const StructSpec& drake_robot_state() {
  static const StructSpec s{{member("utime", "int64_t"), member("num_joints", "int16_t"),
                             per_joint("joint_name", "string"),
                             per_joint("joint_position", "float")}};
  return s;
}

// The members plan_t had when first released, and the four clock members version 2 adds
// after `method`.
StructSpec plan_layout(bool with_clock) {
  StructSpec s{{member("utime", "int64_t"), member("plan_id", "int64_t"),
                member("goal_id", "int64_t"), member("robot", "string"), member("status", "int8_t"),
                member("status_message", "string"), member("method", "string")}};
  if (with_clock) {
    for (const MemberSpec& m :
         {member("clock", "int8_t"), member("start_utime", "int64_t"),
          member("state_utime", "int64_t"), member("takeover_utime", "int64_t")}) {
      s.members.push_back(m);
    }
  }
  const std::vector<Dimension> step_joint = {var("num_steps"), var("num_joints")};
  for (const MemberSpec& m :
       {member("num_joints", "int32_t"), per_joint("joint_name", "string"),
        member("num_steps", "int32_t"), member("t", "double", {var("num_steps")}),
        member("q", "double", step_joint), member("qd", "double", step_joint),
        member("qdd", "double", step_joint), member("tau", "double", step_joint),
        member("solve_time_s", "double"), member("iterations", "int32_t"), member("cost", "double"),
        member("max_dynamics_residual", "double"), member("max_collocation_residual", "double"),
        member("min_clearance", "double"), member("goal_error", "double"),
        member("valid", "boolean")}) {
    s.members.push_back(m);
  }
  return s;
}

// The rule sees a member's name, type and dimensions: changing any one changes the value.
TEST(Fingerprint, RuleSeesMemberNamesTypesAndDimensionsOnly) {
  const StructSpec a{{member("utime", "int64_t"), member("x", "double", {fixed(3)})}};
  const StructSpec renamed_member{{member("utime", "int64_t"), member("y", "double", {fixed(3)})}};
  const StructSpec other_type{{member("utime", "int64_t"), member("x", "float", {fixed(3)})}};
  const StructSpec other_size{{member("utime", "int64_t"), member("x", "double", {fixed(4)})}};
  EXPECT_NE(fingerprint(a), fingerprint(renamed_member));
  EXPECT_NE(fingerprint(a), fingerprint(other_type));
  EXPECT_NE(fingerprint(a), fingerprint(other_size));
}

TEST(Fingerprint, KinographRobotStateMatchesItsLayout) {
  const StructSpec s{{member("utime", "int64_t"), member("robot", "string"),
                      member("num_joints", "int32_t"), per_joint("joint_name", "string"),
                      per_joint("position", "double"), per_joint("velocity", "double")}};
  EXPECT_EQ(robot_state_t::getHash(), fingerprint(s));
}

TEST(Fingerprint, DrakeIiwaStatusMatchesDrakesLayout) {
  const StructSpec s{
      {member("utime", "int64_t"), member("num_joints", "int32_t"),
       per_joint("joint_position_measured", "double"),
       per_joint("joint_velocity_estimated", "double"),
       per_joint("joint_position_commanded", "double"), per_joint("joint_position_ipo", "double"),
       per_joint("joint_torque_measured", "double"), per_joint("joint_torque_commanded", "double"),
       per_joint("joint_torque_external", "double")}};
  EXPECT_EQ(drake::lcmt_iiwa_status::getHash(), fingerprint(s));
}

TEST(Fingerprint, DrakeRobotStateAndPlanMatchDrakesLayout) {
  EXPECT_EQ(drake::lcmt_robot_state::getHash(), fingerprint(drake_robot_state()));
  const StructSpec plan{{member("utime", "int64_t"), member("num_states", "int32_t"),
                         nested("plan", drake_robot_state(), {var("num_states")})}};
  EXPECT_EQ(drake::lcmt_robot_plan::getHash(), fingerprint(plan));
}

TEST(Fingerprint, PlanVersionOneIsTheFirstPlanAndVersionTwoDiffers) {
  EXPECT_EQ(plan_v1_t::getHash(), fingerprint(plan_layout(false)));
  // The fingerprint the first plan_t had on the wire (kinographd's logs until version 2).
  EXPECT_EQ(static_cast<uint64_t>(plan_v1_t::getHash()), 0x9c87cb46fcfb0553u);
  EXPECT_EQ(plan_t::getHash(), fingerprint(plan_layout(true)));
  // Version 2 as released (lcmtypes/README.md): a change to plan_t must be a version 3.
  EXPECT_EQ(static_cast<uint64_t>(plan_t::getHash()), 0xe41f88a8e6fc3556u);
  EXPECT_NE(plan_t::getHash(), plan_v1_t::getHash());
}

TEST(Fingerprint, JointCommandMatchesItsLayout) {
  const StructSpec s{{member("utime", "int64_t"), member("robot", "string"),
                      member("plan_id", "int64_t"), member("num_joints", "int32_t"),
                      per_joint("joint_name", "string"), per_joint("position", "double"),
                      per_joint("velocity", "double"), per_joint("torque", "double")}};
  EXPECT_EQ(joint_command_t::getHash(), fingerprint(s));
}

}  // namespace
}  // namespace kinograph::lcmtypes::testing

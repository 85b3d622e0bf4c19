// Round trips, truncation and fingerprint rejection for every kinograph LCM type, and one
// publish/receive over the in-process memq:// provider.
#include <gtest/gtest.h>

#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <random>
#include <string>
#include <vector>

#include "kinograph/planner_status_v2_t.hpp"
#include "kinograph/planner_status_v3_t.hpp"
#include "lcmtypes/safe_decode.h"
#include "tests/lcmtypes/sample_messages.h"

namespace {

using kinograph::goal_t;
using kinograph::obstacle_list_t;
using kinograph::obstacle_t;
using kinograph::plan_t;
using kinograph::planner_status_t;
using kinograph::robot_state_t;
using namespace kinograph::lcmtypes::testing;

// Decoding what was encoded and encoding it again gives the same bytes: every field survived.
template <typename Msg>
Msg round_trip(const Msg& m) {
  const std::vector<uint8_t> bytes = encode(m);
  Msg out;
  EXPECT_EQ(out.decode(bytes.data(), 0, static_cast<int>(bytes.size())),
            static_cast<int>(bytes.size()));
  EXPECT_EQ(encode(out), bytes);
  return out;
}

// Every strict prefix of a valid message must be rejected, never read past its end.
template <typename Msg>
void expect_truncations_fail(const Msg& m) {
  const std::vector<uint8_t> bytes = encode(m);
  for (size_t len = 0; len < bytes.size(); ++len) {
    std::vector<uint8_t> prefix(bytes.begin(), bytes.begin() + len);  // exact size for ASan
    Msg out;
    EXPECT_LT(out.decode(prefix.data(), 0, static_cast<int>(len)), 0) << "prefix length " << len;
  }
}

TEST(LcmTypes, RobotStateRoundTrip) {
  const robot_state_t m = make_robot_state();
  const robot_state_t out = round_trip(m);
  EXPECT_EQ(out.utime, m.utime);
  EXPECT_EQ(out.robot, "iiwa14");
  EXPECT_EQ(out.joint_name, m.joint_name);
  EXPECT_EQ(out.position, m.position);
  EXPECT_EQ(out.velocity, m.velocity);
}

TEST(LcmTypes, GoalRoundTrip) {
  const goal_t m = make_goal();
  const goal_t out = round_trip(m);
  EXPECT_EQ(out.goal_id, m.goal_id);
  EXPECT_EQ(out.kind, goal_t::KIND_END_EFFECTOR_POSE);
  EXPECT_TRUE(out.joint_position.empty());
  EXPECT_EQ(out.ee_frame, "iiwa_link_ee_kuka");
  for (int i = 0; i < 3; ++i) EXPECT_EQ(out.ee_position[i], m.ee_position[i]);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(out.ee_quaternion[i], m.ee_quaternion[i]);
  EXPECT_EQ(out.duration_s, 2.5);
}

TEST(LcmTypes, JointGoalRoundTrip) {
  goal_t m = make_goal();
  m.kind = goal_t::KIND_JOINT_CONFIGURATION;
  m.joint_position = {3.141592653589793, 0.0};
  m.num_joints = 2;
  const goal_t out = round_trip(m);
  EXPECT_EQ(out.joint_position, m.joint_position);
}

TEST(LcmTypes, ObstacleRoundTrip) {
  const obstacle_t m = make_obstacle("box", obstacle_t::BOX);
  const obstacle_t out = round_trip(m);
  EXPECT_EQ(out.id, "box");
  EXPECT_EQ(out.shape, obstacle_t::BOX);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(out.size[i], m.size[i]);
}

TEST(LcmTypes, ObstacleListRoundTrip) {
  const obstacle_list_t m = make_obstacle_list();
  const obstacle_list_t out = round_trip(m);
  ASSERT_EQ(out.num_obstacles, 4);
  ASSERT_EQ(out.obstacles.size(), 4u);
  EXPECT_EQ(out.obstacles[1].id, "ball");
  EXPECT_EQ(out.obstacles[1].action, obstacle_t::REMOVE);
  EXPECT_EQ(out.obstacles[3].shape, obstacle_t::CAPSULE);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(out.obstacles[2].position[i], m.obstacles[2].position[i]);
  EXPECT_TRUE(out.replace_all);
}

TEST(LcmTypes, PlanRoundTrip) {
  const plan_t m = make_plan(11);
  const plan_t out = round_trip(m);
  EXPECT_EQ(out.plan_id, 5);
  EXPECT_EQ(out.goal_id, m.goal_id);
  EXPECT_EQ(out.method, "incremental");
  EXPECT_EQ(out.t, m.t);
  EXPECT_EQ(out.q, m.q);
  EXPECT_EQ(out.qd, m.qd);
  EXPECT_EQ(out.qdd, m.qdd);
  EXPECT_EQ(out.tau, m.tau);
  EXPECT_EQ(out.min_clearance, m.min_clearance);
  EXPECT_TRUE(out.valid);
  EXPECT_EQ(out.clock, plan_t::CLOCK_ROBOT);
  EXPECT_EQ(out.start_utime, 5'000'000);
  EXPECT_EQ(out.state_utime, 5'000'000);
  EXPECT_EQ(out.takeover_utime, 5'000'000);
}

// A failed plan carries no trajectory; the counts make that explicit and decode agrees.
TEST(LcmTypes, EmptyFailedPlanRoundTrip) {
  plan_t m = make_plan(0);
  m.status = plan_t::INVALID_GOAL;
  m.status_message = "ee_frame 'flange' is not a link of iiwa14";
  m.valid = false;
  const plan_t out = round_trip(m);
  EXPECT_EQ(out.status, plan_t::INVALID_GOAL);
  EXPECT_EQ(out.num_steps, 0);
  EXPECT_TRUE(out.q.empty());
  EXPECT_EQ(out.status_message, m.status_message);
}

TEST(LcmTypes, PlannerStatusRoundTrip) {
  const planner_status_t m = make_planner_status();
  const planner_status_t out = round_trip(m);
  EXPECT_EQ(out.state, planner_status_t::ERROR);
  EXPECT_EQ(out.last_plan_id, -1);
  EXPECT_EQ(out.message, m.message);
  EXPECT_EQ(out.num_failures, 1);
  EXPECT_EQ(out.num_goals_received, 5);
  EXPECT_EQ(out.num_goals_answered, 4);
  EXPECT_EQ(out.num_goals_superseded, 1);
  EXPECT_EQ(out.num_goals_dropped, 2);
  EXPECT_EQ(out.model_id, m.model_id);
  EXPECT_EQ(out.base_position[0], 1.3);
  EXPECT_EQ(out.base_quaternion[0], 1.0);
  EXPECT_EQ(out.goal_utime, 42);
  EXPECT_EQ(out.valid_plan_id, 1);
  EXPECT_EQ(out.num_neighbour_replans, 3);
  EXPECT_EQ(out.neighbours, m.neighbours);
  EXPECT_EQ(out.planning_goal_utime, 43);
}

// Each version of the heartbeat has its own fingerprint; versions 2 and 3 stay readable as
// planner_status_v2_t and planner_status_v3_t and are refused as the current one.
template <class Old>
void expect_old_heartbeat_readable_not_current(Old old) {
  old.robot = "rr";
  old.message = "";
  const std::vector<uint8_t> bytes = encode(old);
  Old back;
  EXPECT_TRUE(kinograph::lcmtypes::safe_decode(bytes.data(), static_cast<int>(bytes.size()), back).ok);
  planner_status_t as_current;
  EXPECT_FALSE(
      kinograph::lcmtypes::safe_decode(bytes.data(), static_cast<int>(bytes.size()), as_current).ok);
}

TEST(LcmTypes, PlannerStatusVersions) {
  EXPECT_NE(kinograph::planner_status_t::getHash(), kinograph::planner_status_v2_t::getHash());
  EXPECT_NE(kinograph::planner_status_t::getHash(), kinograph::planner_status_v3_t::getHash());
  EXPECT_NE(kinograph::planner_status_v2_t::getHash(), kinograph::planner_status_v3_t::getHash());
  expect_old_heartbeat_readable_not_current(kinograph::planner_status_v2_t{});
  kinograph::planner_status_v3_t v3{};
  v3.model_id = "rr:0123456789abcdef";
  v3.neighbours = "";
  expect_old_heartbeat_readable_not_current(v3);
}

TEST(LcmTypes, TruncatedBuffersAreRejected) {
  expect_truncations_fail(make_robot_state());
  expect_truncations_fail(make_goal());
  expect_truncations_fail(make_obstacle("x", obstacle_t::SPHERE));
  expect_truncations_fail(make_obstacle_list());
  expect_truncations_fail(make_plan(3));
  expect_truncations_fail(make_planner_status());
}

// The fingerprint at the head of each message keeps one type from being read as another.
TEST(LcmTypes, FingerprintsDifferAndMismatchIsRejected) {
  const std::vector<int64_t> hashes = {robot_state_t::getHash(),
                                       goal_t::getHash(),
                                       obstacle_t::getHash(),
                                       obstacle_list_t::getHash(),
                                       plan_t::getHash(),
                                       kinograph::plan_v1_t::getHash(),
                                       planner_status_t::getHash(),
                                       kinograph::joint_command_t::getHash(),
                                       kinograph::obstacle_list_v1_t::getHash()};
  for (size_t i = 0; i < hashes.size(); ++i)
    for (size_t j = i + 1; j < hashes.size(); ++j) EXPECT_NE(hashes[i], hashes[j]);

  const std::vector<uint8_t> bytes = encode(make_plan(2));
  goal_t goal;
  EXPECT_LT(goal.decode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  planner_status_t status;
  EXPECT_LT(status.decode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
}

// lcm-cpp 1.3.1 subscribes only member functions (no lambdas), hence this small sink.
class PlanSink {
 public:
  void on_plan(const lcm::ReceiveBuffer*, const std::string& channel, const plan_t* msg) {
    channels.push_back(channel);
    plans.push_back(*msg);
  }
  std::vector<std::string> channels;
  std::vector<plan_t> plans;
};

TEST(LcmTypes, PublishAndReceiveOverMemq) {
  lcm::LCM lc("memq://");
  ASSERT_TRUE(lc.good());
  PlanSink sink;
  lcm::Subscription* sub = lc.subscribe("IIWA_PLAN", &PlanSink::on_plan, &sink);
  ASSERT_NE(sub, nullptr);

  const plan_t sent = make_plan(4);
  ASSERT_EQ(lc.publish("IIWA_PLAN", &sent), 0);
  ASSERT_EQ(lc.publish("ACROBOT_PLAN", &sent), 0);  // another channel: must not be delivered
  for (int i = 0; i < 2; ++i) lc.handleTimeout(100);

  ASSERT_EQ(sink.plans.size(), 1u);
  EXPECT_EQ(sink.channels[0], "IIWA_PLAN");
  EXPECT_EQ(encode(sink.plans[0]), encode(sent));
  lc.unsubscribe(sub);
}

}  // namespace

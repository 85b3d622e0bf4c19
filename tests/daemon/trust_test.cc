// The daemon's trust boundaries, module by module: measured states against the robot's limits,
// strings from the wire bounded, and the rate limit on logging rejected messages.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "daemon/log_limiter.h"
#include "daemon/own_heartbeats.h"
#include "daemon/state_limits.h"
#include "daemon/wire_strings.h"
#include "kinograph/planning/io/scene.h"

namespace kinograph::daemon {
namespace {

// The RR arm as the daemon's integration tests serve it.
const dynamics::Model& rr() {
  static const planning::Scene scene =
      planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/tests/integration/rr_daemon.yaml");
  return *scene.problem.model;
}

messages::MeasuredState state(double q1, double qd1) {
  messages::MeasuredState s;
  s.q = Eigen::Vector2d(q1, 0.0);
  s.qd = Eigen::Vector2d(qd1, 0.0);
  return s;
}

// The RR arm's joint1 is limited to [-pi, pi] rad and 3 rad/s.
TEST(StateLimits, WithinTheToleranceIsAStart) {
  EXPECT_EQ(state_beyond_limits(state(M_PI + 0.9 * kStatePositionTolerance, 0), rr()), "");
  EXPECT_EQ(state_beyond_limits(state(-M_PI - 0.9 * kStatePositionTolerance, 0), rr()), "");
  EXPECT_EQ(state_beyond_limits(state(0, -3.0 * (1 + 0.9 * kStateVelocityTolerance)), rr()), "");
}

TEST(StateLimits, BeyondThePositionLimitNamesTheJointAndTheAmount) {
  const std::string r = state_beyond_limits(state(M_PI + 0.25, 0), rr());
  EXPECT_NE(r.find("joint joint1"), std::string::npos) << r;
  EXPECT_NE(r.find("is 0.25 beyond its limits [-3.14159, 3.14159]"), std::string::npos) << r;
  EXPECT_NE(state_beyond_limits(state(-M_PI - 1.1 * kStatePositionTolerance, 0), rr()), "");
}

TEST(StateLimits, AboveTheVelocityLimitNamesTheJointAndTheAmount) {
  const std::string r = state_beyond_limits(state(0, -3.5), rr());
  EXPECT_NE(r.find("joint joint1: measured velocity -3.5 is 0.5 above its velocity limit 3"),
            std::string::npos)
      << r;
  EXPECT_NE(state_beyond_limits(state(0, 3.0 * (1 + 1.1 * kStateVelocityTolerance)), rr()), "");
}

TEST(StateLimits, NonFiniteIsNeverAStart) {
  EXPECT_NE(state_beyond_limits(state(std::nan(""), 0), rr()), "");
  robot_state_t msg{};
  msg.num_joints = 2;
  msg.joint_name = {"joint1", "joint2"};
  msg.position = {0.0, 0.0};
  msg.velocity = {0.0, std::numeric_limits<double>::infinity()};
  const std::string r = non_finite_joint(msg);
  EXPECT_NE(r.find("joint joint2"), std::string::npos) << r;
  msg.velocity[1] = 0;
  EXPECT_EQ(non_finite_joint(msg), "");
}

TEST(WireStrings, LongStringsAreTruncatedOnACharacterBoundary) {
  EXPECT_EQ(truncated("short"), "short");
  EXPECT_EQ(truncated(std::string(100, 'x'), 10), std::string(10, 'x') + "…");
  // "é" is two bytes: a cut at 4 bytes of "aéé" keeps "aé", never half a character.
  EXPECT_EQ(truncated("a\xC3\xA9\xC3\xA9", 4), "a\xC3\xA9…");
}

TEST(WireStrings, OverlongNamesAreRefusedWithTheirFieldAndLength) {
  goal_t goal{};
  goal.robot = std::string(kMaxWireName, 'r');
  EXPECT_EQ(overlong_name(goal), "");
  goal.robot = std::string(60000, 'r');
  const std::string r = overlong_name(goal);
  EXPECT_NE(r.find("goal_t.robot is 60000 bytes long, more than the 256 allowed"),
            std::string::npos)
      << r;
  EXPECT_LT(r.size(), 200u);

  robot_state_t state{};
  state.joint_name = {"joint1", std::string(300, 'j')};
  EXPECT_NE(overlong_name(state).find("robot_state_t.joint_name[1] is 300 bytes long"),
            std::string::npos);

  obstacle_list_t list{};
  list.obstacles.resize(2);
  list.obstacles[1].id = std::string(257, 'o');
  EXPECT_NE(overlong_name(list).find("obstacle_list_t.obstacles[1].id is 257 bytes long"),
            std::string::npos);
}

TEST(LogLimiter, AtMostNLinesPerWindowThenOneSummary) {
  LogLimiter limiter(3, 1.0);
  const auto t0 = LogLimiter::Clock::time_point{} + std::chrono::hours(1);
  std::vector<std::string> summaries;
  int logged = 0;
  for (int i = 0; i < 20; ++i) {
    logged += limiter.admit("RR_GOAL", t0 + std::chrono::milliseconds(10 * i), summaries);
  }
  EXPECT_EQ(logged, 3);
  EXPECT_TRUE(summaries.empty());
  // Another kind has its own budget.
  EXPECT_TRUE(limiter.admit("RR_STATE", t0, summaries));
  // The next window starts with the summary of the last one's 17 lines left out.
  EXPECT_TRUE(limiter.admit("RR_GOAL", t0 + std::chrono::milliseconds(1500), summaries));
  ASSERT_EQ(summaries.size(), 1u);
  EXPECT_EQ(summaries[0], "… 17 more rejected messages on RR_GOAL in the last 1.5 s");
}

TEST(LogLimiter, FlushSummarisesABurstThatStopped) {
  LogLimiter limiter(1, 1.0);
  const auto t0 = LogLimiter::Clock::time_point{} + std::chrono::hours(1);
  std::vector<std::string> summaries;
  for (int i = 0; i < 5; ++i) limiter.admit("RR_OBSTACLES", t0, summaries);
  EXPECT_TRUE(limiter.flush(t0 + std::chrono::milliseconds(500)).empty());  // window still open
  const auto flushed = limiter.flush(t0 + std::chrono::seconds(2));
  ASSERT_EQ(flushed.size(), 1u);
  EXPECT_EQ(flushed[0], "… 4 more rejected messages on RR_OBSTACLES in the last 2.0 s");
  EXPECT_TRUE(limiter.flush(t0 + std::chrono::seconds(4)).empty());  // said once
}

TEST(OwnHeartbeats, OursAreKnownOthersAreForeignTooOldIsNotJudged) {
  OwnHeartbeats own(3);
  EXPECT_EQ(own.judge(100, 1), OwnHeartbeats::Verdict::kTooOld);  // nothing published yet
  EXPECT_EQ(own.next_utime(100), 100);
  own.record(100, 1);
  EXPECT_EQ(own.next_utime(100), 101);  // strictly increasing, so a utime names one heartbeat
  own.record(101, 2);
  own.record(150, 3);
  EXPECT_EQ(own.judge(101, 2), OwnHeartbeats::Verdict::kOurs);
  EXPECT_EQ(own.judge(101, 9), OwnHeartbeats::Verdict::kForeign);  // same time, other bytes
  EXPECT_EQ(own.judge(120, 2), OwnHeartbeats::Verdict::kForeign);  // a time we never used
  EXPECT_EQ(own.judge(200, 3), OwnHeartbeats::Verdict::kForeign);
  own.record(160, 4);  // forgets 100
  EXPECT_EQ(own.judge(100, 1), OwnHeartbeats::Verdict::kTooOld);
  EXPECT_EQ(own.judge(150, 3), OwnHeartbeats::Verdict::kOurs);
}

}  // namespace
}  // namespace kinograph::daemon

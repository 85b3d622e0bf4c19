// The simulated robot's node over an in-process memq:// LCM, run in the test's own thread (the
// node's handle() delivers the test's subscriptions too, so nothing depends on timing): it holds
// its start against gravity, follows a command, stamps its states on its own clock every 5 ms,
// refuses bad commands and keeps the last good one, and its options (payload error, noise, the
// Drake status) show in what it publishes.
#include "sim/sim_node.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <lcm/lcm-cpp.hpp>
#include <vector>

#include "drake/lcmt_iiwa_status.hpp"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/robot_state_t.hpp"
#include "lcmtypes/safe_decode.h"

namespace kinograph::sim {
namespace {

planning::Scene iiwa_desk() {
  return planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml");
}

class StateSink {
 public:
  void on_state(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    robot_state_t msg;
    ASSERT_TRUE(lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg).ok);
    states.push_back(std::move(msg));
  }
  void on_status(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    drake::lcmt_iiwa_status msg;
    ASSERT_TRUE(lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg).ok);
    statuses.push_back(std::move(msg));
  }
  std::vector<robot_state_t> states;
  std::vector<drake::lcmt_iiwa_status> statuses;
};

class SimNodeFixture : public ::testing::Test {
 protected:
  SimNodeFixture() {
    lcm_.subscribe("IIWA_STATE", &StateSink::on_state, &sink_)->setQueueCapacity(1'000'000);
    lcm_.subscribe("IIWA_STATUS", &StateSink::on_status, &sink_)->setQueueCapacity(1'000'000);
  }
  // Runs a node for `seconds` of simulated time, as fast as the machine allows.
  void run_for(double seconds, SimNodeOptions options = {}) {
    options.channel_prefix = "IIWA";
    options.start_utime = 5'000'000;
    options.duration_s = seconds;
    options.slowdown = 1e-3;
    SimNode node(scene_, options, &lcm_);
    for (const joint_command_t& c : pending_) lcm_.publish("IIWA_COMMAND", &c);
    std::atomic<bool> stop{false};
    node.run(stop);
    while (lcm_.handleTimeout(0) > 0) {  // what the node published last
    }
    tracking_ = node.tracking();
    received_ = node.commands_received();
    refused_ = node.commands_rejected();
  }
  joint_command_t hold_command(const Eigen::VectorXd& q) {
    const dynamics::Model& model = *scene_.problem.model;
    dynamics::Data data(model);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.nq());
    messages::CommandSetpoint s{0, -1, q, zero, dynamics::rnea(model, data, q, zero, zero)};
    return messages::command_to_message(s, model);
  }
  Eigen::VectorXd q_of(const robot_state_t& s) const {
    return Eigen::Map<const Eigen::VectorXd>(s.position.data(), 7);
  }

  planning::Scene scene_ = iiwa_desk();
  lcm::LCM lcm_{"memq://"};
  StateSink sink_;
  std::vector<joint_command_t> pending_;
  TrackingStats tracking_;
  long received_ = 0, refused_ = 0;
};

TEST_F(SimNodeFixture, HoldsItsStartAndStampsStatesOnItsOwnClockEvery5Ms) {
  run_for(0.5);
  ASSERT_EQ(sink_.states.size(), 101u);  // 0, 5, ..., 500 ms
  for (size_t k = 0; k < sink_.states.size(); ++k) {
    EXPECT_EQ(sink_.states[k].utime, 5'000'000 + 5'000 * static_cast<int64_t>(k));
    EXPECT_LT((q_of(sink_.states[k]) - scene_.problem.start_q).cwiseAbs().maxCoeff(), 1e-9);
  }
  EXPECT_EQ(sink_.states[0].joint_name[0], "iiwa_joint_1");
  EXPECT_LT(tracking_.max, 1e-9);
}

// A commanded posture 0.1 rad away on every joint, with its gravity torque: the arm gets there
// and stays within 1e-6 rad of it from 1 s on.
TEST_F(SimNodeFixture, FollowsACommandedPostureAgainstGravity) {
  const Eigen::VectorXd target = scene_.problem.start_q.array() + 0.1;
  pending_ = {hold_command(target)};
  run_for(1.5);
  ASSERT_EQ(received_, 1);
  double late = 0;
  for (const robot_state_t& s : sink_.states) {
    if (s.utime >= 6'000'000) late = std::max(late, (q_of(s) - target).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(late, 1e-6);
  // The step itself counts, at the first state after it. (A step asks the motors for more than
  // their effort limits: saturated, they no longer decouple the arm's modes, and the transient
  // overshoots; the settling above is what the step must show.)
  EXPECT_GE(tracking_.max, 0.1 - 1e-9);
}

// Bad commands are refused and the last good one is held.
TEST_F(SimNodeFixture, RefusesBadCommandsAndHoldsTheLastGoodOne) {
  const Eigen::VectorXd target = scene_.problem.start_q.array() + 0.05;
  joint_command_t wrong_count = hold_command(target);
  wrong_count.num_joints = 6;
  wrong_count.joint_name.pop_back();
  wrong_count.position.pop_back();
  wrong_count.velocity.pop_back();
  wrong_count.torque.pop_back();
  joint_command_t nan = hold_command(target);
  nan.position[2] = std::nan("");
  pending_ = {hold_command(target), wrong_count, nan};
  run_for(1.0);
  EXPECT_EQ(received_, 1);
  EXPECT_EQ(refused_, 2);
  EXPECT_LT((q_of(sink_.states.back()) - target).cwiseAbs().maxCoeff(), 1e-5);
}

// A payload 0.5 kg heavier than the model: the gravity feed-forward falls short and the PD
// loop holds the arm off its setpoint by a visible amount.
TEST_F(SimNodeFixture, APayloadMassErrorMovesTheArmOffItsSetpoint) {
  SimNodeOptions options;
  options.payload_mass_error_kg = 0.5;
  run_for(1.0, options);
  const double sag = (q_of(sink_.states.back()) - scene_.problem.start_q).cwiseAbs().maxCoeff();
  EXPECT_GT(sag, 1e-4);
  EXPECT_LT(sag, 0.05);
  EXPECT_GT(tracking_.max, 1e-4);
}

// Noise on the published states (not on the simulated ones): the deviation seen is the one
// asked for, and the same seed gives the same states.
TEST_F(SimNodeFixture, SensorNoiseIsOnThePublishedStatesAndSeeded) {
  SimNodeOptions options;
  options.position_noise = 1e-3;
  options.seed = 3;
  run_for(1.0, options);
  double sum_sq = 0;
  for (const robot_state_t& s : sink_.states) {
    sum_sq += (q_of(s) - scene_.problem.start_q).squaredNorm();
  }
  EXPECT_NEAR(std::sqrt(sum_sq / (7.0 * sink_.states.size())), 1e-3, 1e-4);
  EXPECT_LT(tracking_.max, 1e-9);  // the arm itself holds still
  const std::vector<robot_state_t> first = sink_.states;
  sink_.states.clear();
  run_for(1.0, options);
  ASSERT_EQ(sink_.states.size(), first.size());
  EXPECT_EQ(sink_.states[10].position, first[10].position);
}

TEST_F(SimNodeFixture, PublishesDrakeIiwaStatusWhenAsked) {
  run_for(0.1);
  EXPECT_TRUE(sink_.statuses.empty());
  sink_.states.clear();
  SimNodeOptions options;
  options.iiwa_status_channel = "IIWA_STATUS";
  run_for(0.1, options);
  ASSERT_EQ(sink_.statuses.size(), 21u);
  EXPECT_EQ(sink_.statuses[3].utime, 5'015'000);
  for (int j = 0; j < 7; ++j) {
    EXPECT_NEAR(sink_.statuses[3].joint_position_measured[j], scene_.problem.start_q[j], 1e-9);
  }
}

TEST(SimNodeOptions, OutOfRangeOptionsAreRefusedByName) {
  lcm::LCM lcm("memq://");
  SimNodeOptions options;
  options.slowdown = 0;
  try {
    SimNode node(iiwa_desk(), options, &lcm);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--slowdown"), std::string::npos) << e.what();
  }
  options.slowdown = 1;
  options.start_utime = -5;
  EXPECT_THROW(SimNode(iiwa_desk(), options, &lcm), std::invalid_argument);
  options.start_utime = 0;
  options.payload_mass_error_kg = -100;  // more than the last link weighs
  try {
    SimNode node(iiwa_desk(), options, &lcm);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--payload-mass-error: "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("link iiwa_link_7"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace kinograph::sim

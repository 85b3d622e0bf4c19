// The executor's node over an in-process memq:// LCM, driven by the test (publish_at with the
// robot's time, so nothing depends on timing): it follows a valid plan on the robot's clock,
// switches at a replan's take-over time without a jump when the replan joins the motion, ignores
// failed plans and refuses plans that do not fit, holds the end, and on a stop request comes to
// rest on a validated stopping trajectory, continuous where it leaves the plan.
#include "execute/executor_node.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <thread>
#include <vector>

#include "kinograph/execution/stopping_trajectory.h"
#include "kinograph/joint_command_t.hpp"
#include "kinograph/planning/trajectory_sampler.h"
#include "kinograph/robot_state_t.hpp"
#include "kinograph/stop_request_t.hpp"
#include "lcmtypes/safe_decode.h"

namespace kinograph::execution {
namespace {

class CommandSink {
 public:
  void on_command(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    joint_command_t msg;
    ASSERT_TRUE(lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg).ok);
    commands.push_back(std::move(msg));
  }
  std::vector<joint_command_t> commands;
};

class ExecutorNodeTest : public ::testing::Test {
 protected:
  ExecutorNodeTest() {
    lcm_.subscribe("IIWA_COMMAND", &CommandSink::on_command, &sink_)->setQueueCapacity(100000);
    ExecutorNodeOptions options;
    options.channel_prefix = "IIWA";
    node_ = std::make_unique<ExecutorNode>(scene_, options, &lcm_);
  }
  const dynamics::Model& model() const { return *scene_.problem.model; }
  // A 1 s motion from (q0, q̇0) with accelerations 0 → a → −a → 0 (rest to rest from rest), as
  // a valid plan (the executor follows what the planner validated; it does not validate them).
  planning::Plan motion(const Eigen::VectorXd& q0, const Eigen::VectorXd& qd0, double a) {
    const Eigen::VectorXd acc = Eigen::VectorXd::Constant(7, a), zero = Eigen::VectorXd::Zero(7);
    planning::Plan plan = linear_acceleration_plan(model(), q0, qd0, {0, 0.25, 0.75, 1.0},
                                                   {zero, acc, -acc, zero}, 5);
    plan.validation.valid = true;
    return plan;
  }
  void send(const planning::Plan& plan, int64_t id, int64_t start, int64_t takeover,
            int64_t state_utime) {
    messages::PlanTime time{plan_t::CLOCK_ROBOT, state_utime, start, state_utime, takeover};
    plan_t msg = messages::plan_to_message(plan, model(), "iiwa14", id, id, time);
    lcm_.publish("IIWA_PLAN", &msg);
  }
  // Delivers what was published (to the node and to the sink).
  void pump() { node_->handle_pending(); }
  Eigen::VectorXd q_of(const joint_command_t& c) const {
    return Eigen::Map<const Eigen::VectorXd>(c.position.data(), 7);
  }
  Eigen::VectorXd qd_of(const joint_command_t& c) const {
    return Eigen::Map<const Eigen::VectorXd>(c.velocity.data(), 7);
  }

  planning::Scene scene_ =
      planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml");
  lcm::LCM lcm_{"memq://"};
  CommandSink sink_;
  std::unique_ptr<ExecutorNode> node_;
};

TEST_F(ExecutorNodeTest, StreamsThePlanOnTheRobotsClock) {
  EXPECT_FALSE(node_->publish_at(0));  // no plan: nothing
  const planning::Plan plan = motion(scene_.problem.start_q, Eigen::VectorXd::Zero(7), 0.4);
  send(plan, 11, 5'000'000, 5'000'000, 5'000'000);
  pump();
  planning::TrajectorySampler sampler(model(), plan);
  for (int64_t t = 5'000'000; t <= 6'500'000; t += 5'000) ASSERT_TRUE(node_->publish_at(t));
  pump();
  ASSERT_EQ(sink_.commands.size(), 301u);
  for (std::size_t i = 0; i < sink_.commands.size(); ++i) {
    const joint_command_t& c = sink_.commands[i];
    EXPECT_EQ(c.utime, 5'000'000 + static_cast<int64_t>(i) * 5'000);
    EXPECT_EQ(c.plan_id, 11);
    const planning::InterpolantPoint p = sampler.at(static_cast<double>(i) * 5e-3);
    EXPECT_LE((q_of(c) - p.q).cwiseAbs().maxCoeff(), 1e-15) << i;
    EXPECT_LE((qd_of(c) - p.qd).cwiseAbs().maxCoeff(), 1e-15) << i;
    EXPECT_LE((Eigen::Map<const Eigen::VectorXd>(c.torque.data(), 7) - p.tau).cwiseAbs().maxCoeff(),
              1e-12)
        << i;
  }
  // After 1 s the last knot is held.
  EXPECT_EQ(q_of(sink_.commands.back()), plan.q.bottomRows(1).transpose());
  EXPECT_LE(qd_of(sink_.commands.back()).cwiseAbs().maxCoeff(), 1e-15);
}

TEST_F(ExecutorNodeTest, SwitchesAtTheTakeOverWithoutAJump) {
  const planning::Plan first = motion(scene_.problem.start_q, Eigen::VectorXd::Zero(7), 0.4);
  send(first, 1, 0, 0, 0);
  pump();
  node_->publish_at(0);
  // A replan from where the first plan will be at 0.4321 s, planned from a state at 0.3 s.
  planning::TrajectorySampler sampler(model(), first);
  const planning::InterpolantPoint join = sampler.at(0.4321);
  send(motion(join.q, join.qd, -0.2), 2, 432'100, 432'100, 300'000);
  pump();
  for (int64_t t = 5'000; t <= 800'000; t += 5'000) node_->publish_at(t);
  node_->publish_at(432'100);
  pump();
  ASSERT_EQ(node_->takeovers().size(), 2u);
  const Takeover& t = node_->takeovers()[1];
  EXPECT_EQ(t.from, 1);
  EXPECT_EQ(t.to, 2);
  EXPECT_EQ(t.utime, 432'100);
  EXPECT_LE(t.jump_q, 1e-6);
  EXPECT_LE(t.jump_qd, 1e-4);
  for (const joint_command_t& c : sink_.commands) EXPECT_EQ(c.plan_id, c.utime < 432'100 ? 1 : 2);
}

TEST_F(ExecutorNodeTest, IgnoresFailedPlansAndRefusesOnesThatDoNotFit) {
  const planning::Plan good = motion(scene_.problem.start_q, Eigen::VectorXd::Zero(7), 0.4);
  send(good, 1, 0, 0, 0);
  planning::Plan failed = good;
  failed.validation.valid = false;
  send(failed, 2, 0, 1'000, 1'000);
  // A plan on the planner's wall clock cannot be placed on the robot's.
  messages::PlanTime wall{plan_t::CLOCK_WALL, 0, 2'000, -1, 2'000};
  plan_t on_wall = messages::plan_to_message(good, model(), "iiwa14", 3, 3, wall);
  lcm_.publish("IIWA_PLAN", &on_wall);
  // Joints in another order.
  plan_t swapped = messages::plan_to_message(good, model(), "iiwa14", 4, 4,
                                             {plan_t::CLOCK_ROBOT, 3'000, 3'000, 3'000, 3'000});
  std::swap(swapped.joint_name[0], swapped.joint_name[1]);
  lcm_.publish("IIWA_PLAN", &swapped);
  plan_t other = messages::plan_to_message(good, model(), "acrobot", 5, 5,
                                           {plan_t::CLOCK_ROBOT, 3'000, 3'000, 3'000, 3'000});
  lcm_.publish("IIWA_PLAN", &other);
  pump();
  node_->publish_at(10'000);
  pump();
  EXPECT_EQ(node_->counters().plans_accepted, 1);
  EXPECT_EQ(node_->counters().plans_ignored, 1);
  EXPECT_EQ(node_->counters().plans_refused, 3);
  ASSERT_EQ(sink_.commands.size(), 1u);
  EXPECT_EQ(sink_.commands[0].plan_id, 1);
}

TEST_F(ExecutorNodeTest, StopsToRestOnAValidatedTrajectory) {
  const planning::Plan plan = motion(scene_.problem.start_q, Eigen::VectorXd::Zero(7), 0.6);
  send(plan, 1, 0, 0, 0);
  pump();
  for (int64_t t = 0; t <= 400'000; t += 5'000) node_->publish_at(t);
  stop_request_t stop{};
  stop.utime = 400'000;
  stop.robot = "iiwa14";
  stop.request_id = 9;
  stop.reason = "test";
  lcm_.publish("IIWA_STOP", &stop);
  pump();
  // A plan planned before the stop (from the state at 300 ms) is not followed afterwards.
  send(plan, 2, 300'000, 300'000, 300'000);
  pump();
  for (int64_t t = 405'000; t <= 4'000'000; t += 5'000) node_->publish_at(t);
  pump();
  EXPECT_EQ(node_->counters().stops, 1);
  EXPECT_EQ(node_->counters().stops_unvalidated, 0);
  EXPECT_EQ(node_->counters().plans_ignored, 1);
  // Continuous where it leaves the plan: the stop starts at the plan's setpoint at 405 ms.
  planning::TrajectorySampler sampler(model(), plan);
  const planning::InterpolantPoint leave = sampler.at(0.405);
  const auto at = [&](int64_t utime) {
    for (const joint_command_t& c : sink_.commands) {
      if (c.utime == utime) return c;
    }
    ADD_FAILURE() << "no command at " << utime;
    return joint_command_t{};
  };
  const joint_command_t first_stop = at(405'000);
  EXPECT_EQ(first_stop.plan_id, -1);
  EXPECT_LE((q_of(first_stop) - leave.q).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LE((qd_of(first_stop) - leave.qd).cwiseAbs().maxCoeff(), 1e-12);
  ASSERT_GT(leave.qd.cwiseAbs().maxCoeff(), 0.1);  // it was moving
  // At rest at the end, and every setpoint of the stop within the velocity limits.
  const joint_command_t last = sink_.commands.back();
  EXPECT_EQ(last.plan_id, -1);
  EXPECT_LE(qd_of(last).cwiseAbs().maxCoeff(), 1e-12);
  for (const joint_command_t& c : sink_.commands) {
    for (int j = 0; j < 7; ++j) {
      EXPECT_LE(std::abs(c.velocity[j]), model().bodies[j].limits.velocity);
    }
  }
  // A plan from a state measured after the stop is followed again.
  send(motion(q_of(last), Eigen::VectorXd::Zero(7), 0.1), 3, 4'100'000, 4'100'000, 4'050'000);
  pump();
  node_->publish_at(4'200'000);
  pump();
  EXPECT_EQ(sink_.commands.back().plan_id, 3);
}

// --rate: run() streams on its own thread at the asked rate of the robot's clock (here the
// wall clock's, read from states the test publishes). A busy machine only spreads the setpoints
// further apart, so the bound is one-sided: at 50 Hz they are never as dense as the default's
// 200 Hz.
TEST(ExecutorNodeRate, StreamsNoFasterThanTheRateAsked) {
  const planning::Scene scene =
      planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml");
  lcm::LCM lcm("memq://");
  std::mutex mutex;
  std::vector<int64_t> utimes;
  struct Sink {
    std::mutex* mutex;
    std::vector<int64_t>* utimes;
    void on(const lcm::ReceiveBuffer* rbuf, const std::string&) {
      joint_command_t msg;
      if (!lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg).ok) return;
      std::lock_guard lock(*mutex);
      utimes->push_back(msg.utime);
    }
  } sink{&mutex, &utimes};
  lcm.subscribe("IIWA_COMMAND", &Sink::on, &sink)->setQueueCapacity(100000);
  ExecutorNodeOptions options;
  options.channel_prefix = "IIWA";
  options.rate_hz = 50;
  ExecutorNode node(scene, options, &lcm);
  const auto wall_us = [] {
    using namespace std::chrono;
    return duration_cast<microseconds>(steady_clock::now().time_since_epoch()).count();
  };
  const int64_t t0 = wall_us();
  // A plan at rest, held: every tick publishes a setpoint.
  const dynamics::Model& model = *scene.problem.model;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(7);
  planning::Plan plan =
      linear_acceleration_plan(model, scene.problem.start_q, zero, {0, 10.0}, {zero, zero}, 1);
  plan.validation.valid = true;
  const plan_t msg =
      messages::plan_to_message(plan, model, "iiwa14", 1, 1, {plan_t::CLOCK_ROBOT, t0, t0, t0, t0});
  lcm.publish("IIWA_PLAN", &msg);
  std::atomic<bool> stop{false};
  std::thread runner([&] { node.run(stop); });
  // States stamped with the wall clock every 5 ms for 1 s (at least 200 of them).
  robot_state_t state{};
  state.robot = "iiwa14";
  state.num_joints = 7;
  for (const auto& body : model.bodies) state.joint_name.push_back(body.joint_name);
  state.position.assign(scene.problem.start_q.data(), scene.problem.start_q.data() + 7);
  state.velocity.assign(7, 0.0);
  for (int i = 0; i < 200; ++i) {
    state.utime = wall_us();
    lcm.publish("IIWA_STATE", &state);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  stop = true;
  runner.join();
  std::lock_guard lock(mutex);
  ASSERT_GE(utimes.size(), 3u);
  const double mean_spacing_us =
      static_cast<double>(utimes.back() - utimes.front()) / static_cast<double>(utimes.size() - 1);
  EXPECT_GT(mean_spacing_us, 0.7 * 20'000) << utimes.size() << " commands";
}

}  // namespace
}  // namespace kinograph::execution

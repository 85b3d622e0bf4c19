// The daemon's node end to end over an in-process memq:// LCM: goals are answered by plans,
// malformed and invalid messages by statuses, obstacle changes trigger replans, and the newest
// goal wins. Real planning on the RR arm; no network.
#include "daemon/planner_node.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "daemon/state_file.h"
#include "tests/daemon/node_listener.h"
#include "tests/daemon/rr_scene.h"
#include "drake/lcmt_iiwa_status.hpp"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/lcm/message_convert.h"
#include "kinograph/planner_status_t.hpp"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/trajectory_sampler.h"
#include "kinograph/planning/validate.h"
#include "lcmtypes/safe_decode.h"
#include "tests/lcmtypes/sample_messages.h"

namespace kinograph::daemon {
namespace {

// A node running on its own thread over one shared memq:// instance.
class NodeFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!defer_start_) start(default_scene());
  }
  void start(planning::Scene scene, PlannerNodeOptions options = {}) {
    create(std::move(scene), options);
    run();
  }
  // The node subscribes when created; what is published before run() waits in LCM's queues,
  // as during a stall.
  void create(planning::Scene scene, PlannerNodeOptions options = {}) {
    ASSERT_TRUE(lcm_.good());
    options.channel_prefix = "RR";
    options.status_period_s = 0.2;
    node_ = std::make_unique<PlannerNode>(std::move(scene), options, &lcm_);
    listener_ = std::make_unique<Listener>(lcm_);
  }
  void run() {
    thread_ = std::thread([this] { node_->run(stop_); });
  }
  static planning::Scene default_scene() {
    return testing::rr_daemon_scene();
  }
  void TearDown() override {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  void send_goal(int64_t id, std::vector<double> q, int64_t utime = 0) {
    goal_t g{};
    g.utime = utime;
    g.goal_id = id;
    g.kind = goal_t::KIND_JOINT_CONFIGURATION;
    g.num_joints = static_cast<int32_t>(q.size());
    g.joint_position = std::move(q);
    g.ee_quaternion[0] = 1;
    lcm_.publish("RR_GOAL", &g);
  }

  void send_obstacle(const std::string& id, int8_t action, double radius,
                     const Eigen::Vector3d& position, bool replace_all = false,
                     const std::string& source = "", int64_t utime = 0) {
    obstacle_list_t list{};
    list.source = source;
    list.utime = utime;
    obstacle_t o{};
    o.id = id;
    o.action = action;
    o.shape = obstacle_t::SPHERE;
    o.size[0] = radius;
    for (int i = 0; i < 3; ++i) o.position[i] = position[i];
    o.quaternion[0] = 1;
    list.obstacles.push_back(o);
    list.num_obstacles = 1;
    list.replace_all = replace_all;
    lcm_.publish("RR_OBSTACLES", &list);
  }

  // A measured state of the RR arm at `utime` on the robot's clock.
  void send_state(int64_t utime, std::vector<double> q, std::vector<double> qd = {0, 0}) {
    robot_state_t state{};
    state.utime = utime;
    state.robot = "rr";
    state.num_joints = 2;
    state.joint_name = {"joint1", "joint2"};
    state.position = std::move(q);
    state.velocity = std::move(qd);
    lcm_.publish("RR_STATE", &state);
  }

  lcm::LCM lcm_{"memq://"};
  bool defer_start_ = false;  // set by fixtures that create and run the node themselves
  std::atomic<bool> stop_{false};
  std::unique_ptr<PlannerNode> node_;
  std::unique_ptr<Listener> listener_;
  std::thread thread_;
};

// Goals of version 2 (goal_v2_t): joints by name, a pose goal or task constraints.
goal_v2_t goal_v2(int64_t id, std::vector<std::string> names, std::vector<double> q) {
  return lcmtypes::testing::joint_goal_by_name(id, std::move(names), std::move(q));
}

// The arm's state with a gripper finger it does not model: the finger is ignored, the goal
// names one joint and the other is held where the state has it.
TEST_F(NodeFixture, GoalByNameMovesTheNamedJointAndHoldsTheOthers) {
  robot_state_t state{};
  state.robot = "rr";
  state.num_joints = 3;
  state.joint_name = {"gripper_finger", "joint2", "joint1"};
  state.position = {0.02, 0.4, -0.8};
  state.velocity = {0, 0, 0};
  lcm_.publish("RR_STATE", &state);
  const goal_v2_t g = goal_v2(21, {"joint1"}, {0.6});
  lcm_.publish("RR_GOAL", &g);
  const auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  const plan_t& p = plans[0];
  ASSERT_EQ(p.status, plan_t::SUCCESS) << p.status_message;
  EXPECT_EQ(p.state_utime, 0);  // planned from the state with the finger in it
  EXPECT_NEAR(p.q.back()[0], 0.6, 1e-3);
  EXPECT_NEAR(p.q.back()[1], 0.4, 1e-3);
  EXPECT_EQ(node_->counters().messages_rejected, 0);
}

TEST_F(NodeFixture, GoalNamingAnUnknownOrRepeatedJointIsRefusedNamingIt) {
  const goal_v2_t unknown = goal_v2(22, {"joint1", "elbow"}, {0.5, 0.2});
  lcm_.publish("RR_GOAL", &unknown);
  const goal_v2_t twice = goal_v2(23, {"joint2", "joint2"}, {0.5, 0.2});
  lcm_.publish("RR_GOAL", &twice);
  const auto plans = listener_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  EXPECT_EQ(plans[0].status, plan_t::INVALID_GOAL);
  EXPECT_NE(plans[0].status_message.find("\"elbow\" is not a joint of rr"), std::string::npos)
      << plans[0].status_message;
  EXPECT_EQ(plans[1].status, plan_t::INVALID_GOAL);
  EXPECT_NE(plans[1].status_message.find("\"joint2\" appears twice"), std::string::npos)
      << plans[1].status_message;
}

TEST_F(NodeFixture, StateMissingAJointIsRefusedNamingIt) {
  robot_state_t state{};
  state.robot = "rr";
  state.num_joints = 2;
  state.joint_name = {"joint1", "joint_2"};
  state.position = {0.1, 0.2};
  state.velocity = {0, 0};
  lcm_.publish("RR_STATE", &state);
  EXPECT_TRUE(listener_->wait_status_containing(
      "robot_state_t names no joint \"joint2\" of rr (it names 1 joint the robot does not "
      "have, e.g. \"joint_2\")"));
}

// The tip's position at (0.8, -0.4) in any orientation: with 2 joints the orientation is
// fixed by the position, so the identity asked for is out of reach unless it is ignored.
TEST_F(NodeFixture, PositionOnlyPoseGoalReachesThePosition) {
  const planning::Scene scene = default_scene();
  const dynamics::Model& model = *scene.problem.model;
  dynamics::Data data(model);
  dynamics::forward_kinematics(model, data, Eigen::Vector2d(0.8, -0.4));
  const Eigen::Vector3d tip = dynamics::frame_pose(model, data, model.frame_index("ee")).translation();
  goal_v2_t g = goal_v2(24, {}, {});
  g.kind = goal_v2_t::KIND_END_EFFECTOR_POSE;
  g.ee_frame = "ee";
  for (int i = 0; i < 3; ++i) g.ee_position[i] = tip[i];
  g.position_only = true;
  lcm_.publish("RR_GOAL", &g);
  const auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  const plan_t& p = plans[0];
  ASSERT_EQ(p.status, plan_t::SUCCESS) << p.status_message;
  dynamics::forward_kinematics(model, data, Eigen::Vector2d(p.q.back()[0], p.q.back()[1]));
  EXPECT_LT((dynamics::frame_pose(model, data, model.frame_index("ee")).translation() - tip).norm(),
            1e-2);
}

// A goal's task constraint holds the tip's orientation at the start's; the joint goal turns
// it by 0.8 rad, so no plan can keep it: the constraint is not ignored.
TEST_F(NodeFixture, GoalTaskConstraintIsPlannedFor) {
  goal_v2_t g = goal_v2(25, {"joint1", "joint2"}, {0.8, -0.4});
  task_constraint_t task{};
  task.frame = "ee";
  task.orientation_only = true;
  const Eigen::Quaterniond start(Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitY()));
  task.quaternion[0] = start.w();
  task.quaternion[1] = start.x();
  task.quaternion[2] = start.y();
  task.quaternion[3] = start.z();
  task.tolerance = 0.05;
  g.task_constraint = {task};
  g.num_task_constraints = 1;
  lcm_.publish("RR_GOAL", &g);
  const auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_NE(plans[0].status, plan_t::SUCCESS);
  EXPECT_NE(plans[0].status_message.find("'ee'"), std::string::npos) << plans[0].status_message;
}

TEST_F(NodeFixture, AnswersAGoalWithAValidPlanThatEndsThere) {
  send_goal(11, {0.9, -0.5});
  auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  const plan_t& p = plans[0];
  EXPECT_EQ(p.goal_id, 11);
  EXPECT_EQ(p.status, plan_t::SUCCESS) << p.status_message;
  ASSERT_GT(p.num_steps, 1);
  EXPECT_NEAR(p.q.back()[0], 0.9, 1e-3);
  EXPECT_NEAR(p.q.back()[1], -0.5, 1e-3);
  EXPECT_NEAR(p.q.front()[0], -0.8, 1e-6);
  EXPECT_TRUE(p.valid);
}

// Before any state the plan is on the daemon's wall clock and starts when it is published.
TEST_F(NodeFixture, WithoutStatesAPlanIsOnTheWallClock) {
  send_goal(15, {0.9, -0.5});
  const auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  const plan_t& p = plans[0];
  ASSERT_EQ(p.status, plan_t::SUCCESS) << p.status_message;
  EXPECT_EQ(p.clock, plan_t::CLOCK_WALL);
  EXPECT_EQ(p.state_utime, -1);
  EXPECT_EQ(p.start_utime, p.utime);
  EXPECT_EQ(p.takeover_utime, p.start_utime);
  EXPECT_GT(p.utime, 1'600'000'000'000'000);  // an epoch time, not a sim time
}

// Sim time: a state at 5 s and a goal at 5.1 s on the robot's clock give a plan stamped on
// that clock, knot 0 at the state's time, whatever the wall clock says.
TEST_F(NodeFixture, WithStatesAPlanIsOnTheRobotClock) {
  send_state(5'000'000, {-0.8, 0.4});
  send_goal(16, {0.9, -0.5}, 5'100'000);
  const auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  const plan_t& p = plans[0];
  ASSERT_EQ(p.status, plan_t::SUCCESS) << p.status_message;
  EXPECT_EQ(p.clock, plan_t::CLOCK_ROBOT);
  EXPECT_EQ(p.state_utime, 5'000'000);
  EXPECT_EQ(p.start_utime, 5'000'000);
  EXPECT_EQ(p.takeover_utime, 5'000'000);
  EXPECT_EQ(p.utime, 5'000'000);  // the robot's clock as the daemon last saw it
  EXPECT_EQ(p.t[0], 0.0);
}

// A goal issued longer after the latest state than the bound (0.5 s by default) is refused,
// with a reason that says how old the state was; the next fresh state lets it plan again.
TEST_F(NodeFixture, AStaleStateRefusesTheGoalWithItsAge) {
  send_state(5'000'000, {-0.8, 0.4});
  send_goal(17, {0.9, -0.5}, 5'600'000);
  auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].goal_id, 17);
  EXPECT_EQ(plans[0].status, plan_t::INVALID_STATE);
  EXPECT_EQ(plans[0].state_utime, 5'000'000);
  EXPECT_EQ(plans[0].clock, plan_t::CLOCK_ROBOT);
  EXPECT_NE(plans[0].status_message.find("0.600000 s older than goal 17"), std::string::npos)
      << plans[0].status_message;
  send_state(5'500'000, {-0.8, 0.4});
  send_goal(18, {0.9, -0.5}, 5'600'000);
  plans = listener_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  EXPECT_EQ(plans[1].status, plan_t::SUCCESS) << plans[1].status_message;
  EXPECT_EQ(plans[1].start_utime, 5'500'000);
  EXPECT_EQ(node_->counters().goals_answered, 2);
}

// A state beyond the robot's limits is never a start: the goal after it is answered
// INVALID_STATE naming the joint and the amount, and the next usable state plans again.
TEST_F(NodeFixture, AStateBeyondTheLimitsIsNeverAStart) {
  send_state(5'000'000, {-0.8, 0.4});
  // (q, q̇) of the state sent before each goal, and what the goal's answer must say.
  struct Case {
    std::vector<double> q, qd;
    int8_t status;
    std::string says;
  };
  const std::vector<Case> cases = {
      {{-0.8, 3.5},
       {0, 0},
       plan_t::INVALID_STATE,  // joint2 is limited to [-pi, pi]
       "joint joint2: measured position 3.5 is 0.358407 beyond"},
      {{-0.8, 0.4},
       {4.0, 0},
       plan_t::INVALID_STATE,  // joint1's velocity limit is 3 rad/s
       "joint joint1: measured velocity 4 is 1 above"},
      {{-0.7, 0.4}, {0, 0}, plan_t::SUCCESS, ""},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const int64_t utime = 5'050'000 + 100'000 * static_cast<int64_t>(i);
    send_state(utime, cases[i].q, cases[i].qd);
    send_goal(21 + static_cast<int64_t>(i), {0.9, -0.5}, utime + 50'000);
    const auto plans = listener_->wait_plans(i + 1);
    ASSERT_EQ(plans.size(), i + 1);
    EXPECT_EQ(plans[i].status, cases[i].status) << plans[i].status_message;
    EXPECT_NE(plans[i].status_message.find(cases[i].says), std::string::npos)
        << plans[i].status_message;
    if (cases[i].status == plan_t::SUCCESS) {
      EXPECT_EQ(plans[i].start_utime, utime);
    }
  }
  EXPECT_EQ(node_->counters().states_refused, 2);
}

// NaN in a measured state (a sensor fault) is answered INVALID_STATE too, with the joint, and
// the older usable state is not planned from in its place.
TEST_F(NodeFixture, ANonFiniteStateIsNeverAStart) {
  send_state(5'000'000, {-0.8, 0.4});
  send_state(5'050'000, {std::nan(""), 0.4});
  send_goal(24, {0.9, -0.5}, 5'100'000);
  const auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].status, plan_t::INVALID_STATE);
  EXPECT_NE(plans[0].status_message.find("joint joint1: position nan"), std::string::npos)
      << plans[0].status_message;
}

// A 60 kB robot name is refused, and neither the answer nor the status echoes it in full.
TEST_F(NodeFixture, AnOverlongNameIsRefusedAndNotEchoed) {
  goal_t g{};
  g.goal_id = 25;
  g.robot = std::string(60000, 'x');
  g.kind = goal_t::KIND_JOINT_CONFIGURATION;
  g.num_joints = 2;
  g.joint_position = {0.9, -0.5};
  g.ee_quaternion[0] = 1;
  lcm_.publish("RR_GOAL", &g);
  const auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].status, plan_t::INVALID_GOAL);
  EXPECT_NE(plans[0].status_message.find("goal_t.robot is 60000 bytes long"), std::string::npos)
      << plans[0].status_message;
  EXPECT_LT(plans[0].status_message.size(), 300u);
  ASSERT_TRUE(listener_->wait_status_containing("goal_t.robot is 60000 bytes long"));
  const auto status = listener_->wait_status_answered(1);
  ASSERT_TRUE(status);
  EXPECT_LT(status->message.size(), 300u);
}

// A node hears its own heartbeats and takes them as its own; a heartbeat on its status channel
// that it did not publish (here the test's, standing in for a second daemon on prefix RR; two
// real daemons: tests/daemon/second_daemon_test.sh) is reported in its heartbeat.
TEST_F(NodeFixture, AHeartbeatOfASecondDaemonIsReported) {
  ASSERT_TRUE(listener_->wait_statuses(5));  // the node's own heartbeats, read back by it too
  EXPECT_EQ(node_->counters().foreign_heartbeats, 0);
  planner_status_t other{};
  other.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                    std::chrono::system_clock::now().time_since_epoch())
                    .count();
  other.robot = "rr";
  other.last_plan_id = 7;
  lcm_.publish("RR_PLANNER_STATUS", &other);
  EXPECT_TRUE(listener_->wait_status_containing(
      "another planner daemon publishes on RR_PLANNER_STATUS (robot \"rr\", its last plan id 7)"));
  EXPECT_EQ(node_->counters().foreign_heartbeats, 1);
}

class StateAgeFixture : public NodeFixture {
 protected:
  StateAgeFixture() { defer_start_ = true; }
};

// --max-state-age: the same 0.6 s old state is accepted under a 1 s bound.
TEST_F(StateAgeFixture, TheStateAgeBoundIsTheOptionsOne) {
  PlannerNodeOptions options;
  options.max_state_age_s = 1.0;
  start(default_scene(), options);
  send_state(5'000'000, {-0.8, 0.4});
  send_goal(19, {0.9, -0.5}, 5'600'000);
  const auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].status, plan_t::SUCCESS) << plans[0].status_message;
  EXPECT_EQ(plans[0].start_utime, 5'000'000);
}

// Drake's iiwa status names no robot: one with NaN is refused as malformed, naming the field
// and joint, and dropped as if lost; the usable status before it is still the start.
TEST_F(StateAgeFixture, ANonFiniteIiwaStatusIsRefusedAsMalformed) {
  PlannerNodeOptions options;
  options.iiwa_status_channel = "RR_IIWA_STATUS";
  start(default_scene(), options);
  const auto status = [&](int64_t utime, double q1) {
    drake::lcmt_iiwa_status m;
    m.utime = utime;
    m.num_joints = 2;
    for (auto* v : {&m.joint_position_measured, &m.joint_velocity_estimated,
                    &m.joint_position_commanded, &m.joint_position_ipo, &m.joint_torque_measured,
                    &m.joint_torque_commanded, &m.joint_torque_external}) {
      v->assign(2, 0.0);
    }
    m.joint_position_measured = {-0.8, q1};
    lcm_.publish("RR_IIWA_STATUS", &m);
  };
  status(5'000'000, 0.4);
  status(5'050'000, std::nan(""));
  ASSERT_TRUE(listener_->wait_status_containing(
      "RR_IIWA_STATUS: malformed lcmt_iiwa_status.joint_position_measured[1] (joint joint2) is "
      "nan"));
  send_goal(26, {0.9, -0.5}, 5'100'000);
  const auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].status, plan_t::SUCCESS) << plans[0].status_message;
  EXPECT_EQ(plans[0].start_utime, 5'000'000);
  EXPECT_EQ(node_->counters().messages_rejected, 1);
  EXPECT_EQ(node_->counters().states_refused, 0);
}

// A restarted node with the same --state-file continues the plan ids and still knows the
// obstacle received over LCM before the restart; without one it says the world was forgotten.
TEST_F(StateAgeFixture, AStateFileKeepsPlanIdsAndObstaclesAcrossARestart) {
  const std::string path =
      ::testing::TempDir() + "kinograph_restart_" + std::to_string(::getpid()) + ".state";
  std::remove(path.c_str());
  PlannerNodeOptions options;
  options.state_file = path;
  start(default_scene(), options);
  send_goal(1, {0.8, -0.4});
  auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].plan_id, 1);
  EXPECT_GT(plans[0].min_clearance, 0.5);                                  // nothing near the arm
  send_obstacle("ball", obstacle_t::ADD_OR_MOVE, 0.05, {0.0, 0.0, 1.85});  // in its way
  plans = listener_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  EXPECT_EQ(plans[1].plan_id, 2);

  // Restart: a new node on the same file (the listener stays subscribed).
  stop_ = true;
  thread_.join();
  node_.reset();
  stop_ = false;
  options.channel_prefix = "RR";
  options.status_period_s = 0.2;
  node_ = std::make_unique<PlannerNode>(default_scene(), options, &lcm_);
  run();
  send_goal(1, {0.8, -0.4});  // a restarted sender numbers from 1 again
  plans = listener_->wait_plans(3);
  ASSERT_EQ(plans.size(), 3u);
  EXPECT_EQ(plans[2].plan_id, 3);
  EXPECT_EQ(plans[2].status, plan_t::SUCCESS) << plans[2].status_message;
  EXPECT_LT(plans[2].min_clearance, 0.5) << "the ball was forgotten";
  EXPECT_GE(plans[2].min_clearance, 0.0);
  std::remove(path.c_str());
}

// A corrupt state file stops the node from starting, naming the file.
TEST_F(StateAgeFixture, ACorruptStateFileIsRefused) {
  const std::string path =
      ::testing::TempDir() + "kinograph_corrupt_" + std::to_string(::getpid()) + ".state";
  std::ofstream(path) << "{\"format\": \"kinographd state\", \"version\": 1,";
  PlannerNodeOptions options;
  options.state_file = path;
  try {
    PlannerNode node(default_scene(), options, &lcm_);
    FAIL() << "a corrupt state file was taken";
  } catch (const StateFileError& e) {
    EXPECT_NE(std::string(e.what()).find("state file '" + path + "': is not valid JSON"),
              std::string::npos)
        << e.what();
  }
  std::remove(path.c_str());
}

// Obstacles are per source: another source's replace_all (here a version-1 sender's, the
// unnamed source) leaves perception's ball in the world; perception's own removes it.
TEST_F(NodeFixture, AReplaceAllReplacesOnlyItsSourcesObstacles) {
  send_goal(1, {0.8, -0.4});
  auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_GT(plans[0].min_clearance, 0.5);
  send_obstacle("ball", obstacle_t::ADD_OR_MOVE, 0.05, {0.0, 0.0, 1.85}, false, "perception");
  plans = listener_->wait_plans(2);  // the replan around the ball
  ASSERT_EQ(plans.size(), 2u);
  EXPECT_LT(plans[1].min_clearance, 0.5);

  kinograph::obstacle_list_v1_t wipe{};  // an old sender's empty replace_all
  wipe.replace_all = true;
  lcm_.publish("RR_OBSTACLES", &wipe);
  // The same id from the operator is another obstacle, far away.
  send_obstacle("ball", obstacle_t::ADD_OR_MOVE, 0.05, {0.0, 3.0, 0.0}, true, "operator");
  plans = listener_->wait_plans(3);  // the operator's ball is a change: one replan
  ASSERT_EQ(plans.size(), 3u);
  EXPECT_LT(plans[2].min_clearance, 0.5) << "perception's ball was wiped by another source";
  send_goal(2, {0.8, -0.4});
  plans = listener_->wait_plans(4);
  ASSERT_EQ(plans.size(), 4u);
  EXPECT_LT(plans[3].min_clearance, 0.5);

  obstacle_list_t own{};
  own.source = "perception";
  own.replace_all = true;
  lcm_.publish("RR_OBSTACLES", &own);
  plans = listener_->wait_plans(5);
  ASSERT_EQ(plans.size(), 5u);
  EXPECT_GT(plans[4].min_clearance, 0.5) << "perception's own replace_all kept its ball";
  EXPECT_EQ(node_->counters().messages_rejected, 0);
}

TEST_F(NodeFixture, MalformedBytesGetAStatusAndTheNodeKeepsServing) {
  const char garbage[] = "\x01\x02\x03 not an LCM goal";
  lcm_.publish("RR_GOAL", garbage, sizeof(garbage));
  EXPECT_TRUE(listener_->wait_status_containing("malformed goal_t"));
  send_goal(12, {0.5, 0.5});
  auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].goal_id, 12);
  EXPECT_EQ(node_->counters().messages_rejected, 1);
}

TEST_F(NodeFixture, AnInvalidGoalIsAnsweredWithInvalidGoal) {
  send_goal(13, {0.5});  // one joint for a two-joint arm
  auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].goal_id, 13);
  EXPECT_EQ(plans[0].status, plan_t::INVALID_GOAL);
  EXPECT_NE(plans[0].status_message.find("num_joints"), std::string::npos);

  send_goal(14, {10.0, 0.0});  // outside the joint limits: the planner's own check
  plans = listener_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  EXPECT_EQ(plans[1].goal_id, 14);
  EXPECT_EQ(plans[1].status, plan_t::INVALID_GOAL) << plans[1].status_message;
  // The answer carries the planner's reason in the user's terms.
  EXPECT_NE(plans[1].status_message.find("goal joint 1 (joint1) = 10 rad is outside its limits"),
            std::string::npos)
      << plans[1].status_message;
}

TEST_F(NodeFixture, AnObstacleInThePathTriggersACollisionFreeReplan) {
  send_goal(15, {0.8, -0.4});
  auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans[0].status, plan_t::SUCCESS) << plans[0].status_message;
  EXPECT_GT(plans[0].min_clearance, 0.5);  // nothing in the scene yet
  // The first plan's tip passes within the ball-to-be (radius 0.05 + link radius 0.04).
  const auto model =
      dynamics::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/rr/rr.urdf");
  dynamics::Data data(model);
  double closest = 1e9;
  for (const auto& q : plans[0].q) {
    dynamics::forward_kinematics(model, data, Eigen::Map<const Eigen::VectorXd>(q.data(), 2));
    const Eigen::Vector3d tip =
        dynamics::frame_pose(model, data, model.frame_index("ee")).translation();
    closest = std::min(closest, (tip - Eigen::Vector3d(0, 0, 1.85)).norm());
  }
  EXPECT_LT(closest, 0.09) << "the ball would not be in the first plan's way";

  // A small ball just above where the tip passes when the arm is upright (q ≈ 0: links along
  // +z, tip at 1.8 m): the first plan hits it; bending the elbow a little more clears it.
  obstacle_list_t obstacles{};
  obstacle_t o{};
  o.id = "ball";
  o.action = obstacle_t::ADD_OR_MOVE;
  o.shape = obstacle_t::SPHERE;
  o.size[0] = 0.05;
  o.position[0] = 0.0;
  o.position[2] = 1.85;
  o.quaternion[0] = 1;
  obstacles.obstacles.push_back(o);
  obstacles.num_obstacles = 1;
  lcm_.publish("RR_OBSTACLES", &obstacles);

  plans = listener_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  EXPECT_EQ(plans[1].goal_id, 15);
  EXPECT_EQ(plans[1].status, plan_t::SUCCESS) << plans[1].status_message;
  EXPECT_GE(plans[1].min_clearance, 0.0);
  EXPECT_EQ(node_->counters().replans, 1);
}

// While an executor follows the daemon's plan (its commands name it), a replan starts where
// that plan is at the latest state's time plus --takeover-latency and takes over there, so the
// commanded motion is continuous; without such commands plans start at the measured state.
TEST_F(NodeFixture, AReplanWhileAnExecutorFollowsJoinsTheMotion) {
  send_state(1'000'000, {-0.8, 0.4});
  send_goal(15, {0.8, -0.4}, 1'000'000);
  auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans[0].status, plan_t::SUCCESS) << plans[0].status_message;
  EXPECT_EQ(plans[0].takeover_utime, 1'000'000);
  // The executor's setpoint of that plan, then a state the robot measured 0.2 s in.
  const dynamics::Model model =
      dynamics::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/rr/rr.urdf");
  const planning::Plan first = messages::plan_from_message(plans[0]);
  planning::TrajectorySampler sampler(model, first);
  const planning::InterpolantPoint at_state = sampler.at(0.2);
  messages::CommandSetpoint setpoint{1'200'000, plans[0].plan_id, at_state.q, at_state.qd,
                                     at_state.tau};
  const joint_command_t command = messages::command_to_message(setpoint, model);
  lcm_.publish("RR_COMMAND", &command);
  send_state(1'200'000, {at_state.q[0] + 0.01, at_state.q[1]}, {at_state.qd[0], at_state.qd[1]});
  send_obstacle("ball", obstacle_t::ADD_OR_MOVE, 0.05, {0, 0, 1.85}, false, "", 1'200'000);
  plans = listener_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  const plan_t& replan = plans[1];
  ASSERT_EQ(replan.status, plan_t::SUCCESS) << replan.status_message;
  EXPECT_EQ(replan.state_utime, 1'200'000);
  EXPECT_EQ(replan.takeover_utime, 1'200'000 + 300'000);  // the default latency
  EXPECT_EQ(replan.start_utime, replan.takeover_utime);
  // Knot 0 is the first plan at the take-over (0.5 s in), not the measured state.
  const planning::InterpolantPoint join = sampler.at(0.5);
  for (int j = 0; j < 2; ++j) {
    EXPECT_LE(std::abs(replan.q[0][j] - join.q[j]), 1e-6) << j;
    EXPECT_LE(std::abs(replan.qd[0][j] - join.qd[j]), 1e-4) << j;
  }
  EXPECT_EQ(node_->counters().joined, 1);
  EXPECT_EQ(node_->counters().late_takeovers, 0);
}

// --takeover-latency sets how far after the latest state a joining replan takes over.
class LatencyNodeFixture : public NodeFixture {
 protected:
  LatencyNodeFixture() { defer_start_ = true; }
};

TEST_F(LatencyNodeFixture, TheTakeOverLatencyIsTheOptionsValue) {
  PlannerNodeOptions options;
  options.takeover_latency_s = 0.12;
  start(default_scene(), options);
  send_state(1'000'000, {-0.8, 0.4});
  send_goal(15, {0.8, -0.4}, 1'000'000);
  auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans[0].status, plan_t::SUCCESS) << plans[0].status_message;
  const dynamics::Model model =
      dynamics::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/rr/rr.urdf");
  messages::CommandSetpoint setpoint{1'100'000, plans[0].plan_id, Eigen::Vector2d(-0.8, 0.4),
                                     Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  const joint_command_t command = messages::command_to_message(setpoint, model);
  lcm_.publish("RR_COMMAND", &command);
  send_state(1'100'000, {-0.8, 0.4});
  send_obstacle("ball", obstacle_t::ADD_OR_MOVE, 0.05, {0, 0, 1.85}, false, "", 1'100'000);
  plans = listener_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  ASSERT_EQ(plans[1].status, plan_t::SUCCESS) << plans[1].status_message;
  EXPECT_EQ(plans[1].takeover_utime, 1'100'000 + 120'000);
}

// An executor that stopped (commands of no plan) is not joined: the replan starts at the state.
TEST_F(NodeFixture, AfterAStopTheReplanStartsAtTheMeasuredState) {
  send_state(1'000'000, {-0.8, 0.4});
  send_goal(15, {0.8, -0.4}, 1'000'000);
  auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans[0].status, plan_t::SUCCESS) << plans[0].status_message;
  const dynamics::Model model =
      dynamics::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/rr/rr.urdf");
  messages::CommandSetpoint hold{1'200'000, -1, Eigen::Vector2d(-0.7, 0.3), Eigen::Vector2d::Zero(),
                                 Eigen::Vector2d::Zero()};
  const joint_command_t command = messages::command_to_message(hold, model);
  lcm_.publish("RR_COMMAND", &command);
  send_state(1'200'000, {-0.7, 0.3});
  send_obstacle("ball", obstacle_t::ADD_OR_MOVE, 0.05, {0, 0, 1.85}, false, "", 1'200'000);
  plans = listener_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  ASSERT_EQ(plans[1].status, plan_t::SUCCESS) << plans[1].status_message;
  EXPECT_EQ(plans[1].takeover_utime, 1'200'000);
  EXPECT_NEAR(plans[1].q[0][0], -0.7, 1e-6);
  EXPECT_EQ(node_->counters().joined, 0);
}

// An obstacle update stamped later than the latest state by more than --max-state-age replans
// nothing from that state: the goal is answered INVALID_STATE, naming the update.
TEST_F(NodeFixture, AnObstacleUpdateChecksTheStatesAge) {
  send_state(1'000'000, {-0.8, 0.4});
  send_goal(15, {0.8, -0.4}, 1'000'000);
  auto plans = listener_->wait_plans(1);
  ASSERT_EQ(plans[0].status, plan_t::SUCCESS) << plans[0].status_message;
  send_obstacle("ball", obstacle_t::ADD_OR_MOVE, 0.05, {0, 0, 1.85}, false, "", 1'700'000);
  plans = listener_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  EXPECT_EQ(plans[1].goal_id, 15);
  EXPECT_EQ(plans[1].status, plan_t::INVALID_STATE);
  EXPECT_NE(plans[1].status_message.find("0.700000 s older than the obstacle update for goal 15"),
            std::string::npos)
      << plans[1].status_message;
  EXPECT_EQ(node_->counters().goals_answered, 1);  // a replan's answer is not a new answer
}

TEST_F(NodeFixture, NewestGoalWinsAndEveryGoalIsAnswered) {
  for (int i = 0; i < 4; ++i) send_goal(20 + i, {0.2 * i, 0.1});
  // Each goal gets exactly one answer: planned, or superseded because a newer one came first.
  auto plans = listener_->wait_plans(4);
  ASSERT_EQ(plans.size(), 4u);
  std::set<int64_t> answered;
  for (const auto& p : plans) {
    EXPECT_TRUE(answered.insert(p.goal_id).second) << "goal " << p.goal_id << " answered twice";
    EXPECT_TRUE(p.status == plan_t::SUCCESS || p.status == plan_t::SUPERSEDED);
  }
  EXPECT_EQ(answered, (std::set<int64_t>{20, 21, 22, 23}));
  const auto newest =
      std::find_if(plans.begin(), plans.end(), [](const plan_t& p) { return p.goal_id == 23; });
  EXPECT_EQ(newest->status, plan_t::SUCCESS);
}

// Goals that piled up while the node was not handling LCM (a stall) are answered whole: the
// newest planned, every older one SUPERSEDED, and the heartbeat accounts for each.
class StalledNodeFixture : public NodeFixture {
 protected:
  StalledNodeFixture() { defer_start_ = true; }
};

TEST_F(StalledNodeFixture, ABurstWaitingInLcmIsAnsweredWholeAndOnlyTheNewestPlanned) {
  create(default_scene());
  constexpr int kBurst = 40;  // more than LCM's default queue of 30
  for (int i = 0; i < kBurst; ++i) send_goal(100 + i, {0.5 + 0.01 * i, -0.2});
  run();
  auto plans = listener_->wait_plans(kBurst);
  ASSERT_EQ(plans.size(), static_cast<size_t>(kBurst));
  std::set<int64_t> answered;
  for (const auto& p : plans) {
    EXPECT_TRUE(answered.insert(p.goal_id).second) << "goal " << p.goal_id << " answered twice";
    if (p.goal_id == 100 + kBurst - 1) {
      EXPECT_EQ(p.status, plan_t::SUCCESS) << p.status_message;
      EXPECT_TRUE(p.valid);
      EXPECT_NEAR(p.q.back()[0], 0.5 + 0.01 * (kBurst - 1), 1e-3);
    } else {
      EXPECT_EQ(p.status, plan_t::SUPERSEDED) << "goal " << p.goal_id;
      EXPECT_NE(p.status_message.find("superseded by goal 139"), std::string::npos)
          << p.status_message;
    }
  }
  EXPECT_EQ(answered.size(), static_cast<size_t>(kBurst));
  const auto status = listener_->wait_status_answered(kBurst);
  ASSERT_TRUE(status);
  EXPECT_EQ(status->num_goals_received, kBurst);
  EXPECT_EQ(status->num_goals_answered, kBurst);
  EXPECT_EQ(status->num_goals_superseded, kBurst - 1);
  EXPECT_EQ(status->num_goals_dropped, 0);
  const NodeCounters c = node_->counters();
  EXPECT_EQ(c.goals_superseded, kBurst - 1);
  EXPECT_EQ(c.plans_published, kBurst);
}

// Goal ids 31 and 32 never arrive: goal 33 reveals the gap, both are answered SUPERSEDED and
// counted as dropped, and received + dropped = answered.
TEST_F(NodeFixture, SkippedGoalIdsAreAnsweredAndCountedAsDropped) {
  send_goal(30, {0.5, 0.1});
  ASSERT_EQ(listener_->wait_plans(1).size(), 1u);
  send_goal(33, {0.6, 0.1});
  auto plans = listener_->wait_plans(4);
  ASSERT_EQ(plans.size(), 4u);
  EXPECT_EQ(plans[1].goal_id, 31);
  EXPECT_EQ(plans[2].goal_id, 32);
  for (int k : {1, 2}) {
    EXPECT_EQ(plans[k].status, plan_t::SUPERSEDED);
    EXPECT_NE(plans[k].status_message.find("lost in transport"), std::string::npos)
        << plans[k].status_message;
  }
  EXPECT_EQ(plans[3].goal_id, 33);
  EXPECT_EQ(plans[3].status, plan_t::SUCCESS) << plans[3].status_message;
  const auto status = listener_->wait_status_answered(4);
  ASSERT_TRUE(status);
  EXPECT_EQ(status->num_goals_received, 2);
  EXPECT_EQ(status->num_goals_dropped, 2);
  EXPECT_EQ(status->num_goals_answered, 4);
  EXPECT_EQ(status->num_goals_superseded, 2);
}

// With answer_goal_id_gaps off (ids carry no sequence), a jump in ids answers nothing extra.
TEST_F(StalledNodeFixture, GoalIdGapsAreIgnoredWhenAsked) {
  PlannerNodeOptions options;
  options.answer_goal_id_gaps = false;
  start(default_scene(), options);
  send_goal(30, {0.5, 0.1});
  ASSERT_EQ(listener_->wait_plans(1).size(), 1u);
  send_goal(33, {0.6, 0.1});
  // Any answer for 31 or 32 would come before 33's plan (the worker answers first, then plans).
  auto plans = listener_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  EXPECT_EQ(plans[1].goal_id, 33);
  EXPECT_EQ(plans[1].status, plan_t::SUCCESS) << plans[1].status_message;
  const auto status = listener_->wait_status_answered(2);
  ASSERT_TRUE(status);
  EXPECT_EQ(status->num_goals_dropped, 0);
  EXPECT_EQ(status->num_goals_received, 2);
}

// An invalid goal is received and answered (INVALID_GOAL), so the accounting still closes.
TEST_F(NodeFixture, AnInvalidGoalCountsAsReceivedAndAnswered) {
  send_goal(40, {0.5});
  ASSERT_EQ(listener_->wait_plans(1).size(), 1u);
  const auto status = listener_->wait_status_answered(1);
  ASSERT_TRUE(status);
  EXPECT_EQ(status->num_goals_received, 1);
  EXPECT_EQ(status->num_goals_answered, 1);
  EXPECT_EQ(status->num_goals_superseded, 0);
}

// Replanning on the RR reach scene (robots/scenes/rr_reach.yaml: swing from leaning left to
// leaning right past a fixed ball above the upright pose). Fixed obstacles come from the scene;
// the tests add a "pebble" over LCM.
class ReplanFixture : public NodeFixture {
 protected:
  ReplanFixture() { defer_start_ = true; }
  void start_reach(PlannerNodeOptions options = {}) {
    scene_ =
        planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/rr_reach.yaml");
    start(scene_, options);
  }
  // The scene's problem with `goal` and, optionally, a pebble: what a published plan must
  // validate against.
  planning::Problem problem_with(const Eigen::Vector2d& goal,
                                 std::optional<Eigen::Vector3d> pebble = std::nullopt) const {
    planning::Problem p = scene_.problem;
    p.goal.q = goal;
    if (pebble) {
      collision::Obstacle o;
      o.id = 100;
      o.shape = collision::Shape::sphere(kPebbleRadius);
      o.pose.translation() = *pebble;
      p.obstacles.push_back(o);
    }
    return p;
  }
  static planning::Validation check(const planning::Problem& problem, const plan_t& msg) {
    return planning::validate(problem, messages::plan_from_message(msg));
  }
  // Where the tip of the arm is at step k of a plan.
  Eigen::Vector3d tip_at(const plan_t& plan, int k) const {
    const dynamics::Model& model = *scene_.problem.model;
    dynamics::Data data(model);
    dynamics::forward_kinematics(model, data,
                                 Eigen::Map<const Eigen::VectorXd>(plan.q[k].data(), 2));
    return dynamics::frame_pose(model, data, model.frame_index("ee")).translation();
  }
  static std::string describe(const plan_t& p) {
    return p.method + ", status " + std::to_string(p.status) + ": " + p.status_message;
  }
  // Sends a goal and returns the plan answering it (the n-th plan overall).
  plan_t plan_goal(int64_t id, const Eigen::Vector2d& q, size_t n) {
    send_goal(id, {q[0], q[1]});
    auto plans = listener_->wait_plans(n);
    EXPECT_EQ(plans.size(), n);
    return plans.size() >= n ? plans[n - 1] : plan_t{};
  }

  static constexpr double kPebbleRadius = 0.05;
  const Eigen::Vector2d kGoal{1.2, 0.0};  // the scene's goal
  planning::Scene scene_;
};

// An obstacle moved onto the current plan's path: the replan is incremental, validates against
// the scene with the obstacle where it now is, and the first plan would not have.
TEST_F(ReplanFixture, ObstacleMovedIntoThePathReplansIncrementally) {
  start_reach();
  const plan_t first = plan_goal(1, kGoal, 1);
  ASSERT_EQ(first.status, plan_t::SUCCESS) << describe(first);
  EXPECT_EQ(first.method, "batch");

  // Out of reach first (an addition), then onto the path (a move of the same obstacle).
  send_obstacle("pebble", obstacle_t::ADD_OR_MOVE, kPebbleRadius, {0, 3, 0});
  auto plans = listener_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  EXPECT_EQ(plans[1].status, plan_t::SUCCESS) << describe(plans[1]);
  EXPECT_EQ(plans[1].method, "incremental");

  // On the tip's path a third of the way, pushed 5 cm outward from the shoulder: the first plan
  // runs through it.
  const Eigen::Vector3d tip = tip_at(first, 10);
  const Eigen::Vector3d pebble = tip + 0.05 * tip.normalized();
  ASSERT_FALSE(check(problem_with(kGoal, pebble), first).valid) << "the pebble must be in the way";
  send_obstacle("pebble", obstacle_t::ADD_OR_MOVE, kPebbleRadius, pebble);
  plans = listener_->wait_plans(3);
  ASSERT_EQ(plans.size(), 3u);
  const plan_t& replan = plans[2];
  EXPECT_EQ(replan.goal_id, 1);
  ASSERT_EQ(replan.status, plan_t::SUCCESS) << describe(replan);
  EXPECT_EQ(replan.method, "incremental");
  const planning::Validation v = check(problem_with(kGoal, pebble), replan);
  EXPECT_TRUE(v.valid) << (v.failures.empty() ? "" : v.failures.front());
  EXPECT_GE(v.min_clearance, 0.0);
  const NodeCounters c = node_->counters();
  EXPECT_EQ(c.replans, 2);
  EXPECT_EQ(c.incremental, 2);
  EXPECT_EQ(c.fallbacks, 0);
}

// A second goal near the first: an incremental replan that ends at the new goal and validates.
TEST_F(ReplanFixture, NearbyGoalReplansIncrementally) {
  start_reach();
  ASSERT_EQ(plan_goal(1, kGoal, 1).status, plan_t::SUCCESS);
  const Eigen::Vector2d goal(1.05, 0.2);
  const plan_t p = plan_goal(2, goal, 2);
  EXPECT_EQ(p.goal_id, 2);
  ASSERT_EQ(p.status, plan_t::SUCCESS) << describe(p);
  EXPECT_EQ(p.method, "incremental");
  EXPECT_NEAR(p.q.back()[0], goal[0], 1e-2);
  EXPECT_NEAR(p.q.back()[1], goal[1], 1e-2);
  EXPECT_TRUE(check(problem_with(goal), p).valid);
}

// A goal naming a duration changes the horizon (same step count) within the incremental replan;
// the next goal without one returns to the scene's horizon.
TEST_F(ReplanFixture, GoalDurationChangesTheHorizon) {
  start_reach();
  ASSERT_EQ(plan_goal(1, kGoal, 1).status, plan_t::SUCCESS);
  goal_t g{};
  g.goal_id = 2;
  g.kind = goal_t::KIND_JOINT_CONFIGURATION;
  g.num_joints = 2;
  g.joint_position = {1.1, 0.1};
  g.ee_quaternion[0] = 1;
  g.duration_s = 3.5;
  lcm_.publish("RR_GOAL", &g);
  auto plans = listener_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  ASSERT_EQ(plans[1].status, plan_t::SUCCESS) << describe(plans[1]);
  EXPECT_EQ(plans[1].method, "incremental");
  EXPECT_NEAR(plans[1].t.back(), 3.5, 1e-9);
  planning::Problem longer = problem_with(Eigen::Vector2d(1.1, 0.1));
  longer.horizon = 3.5;
  EXPECT_TRUE(check(longer, plans[1]).valid);
  const plan_t back = plan_goal(3, kGoal, 3);
  ASSERT_EQ(back.status, plan_t::SUCCESS) << describe(back);
  EXPECT_NEAR(back.t.back(), scene_.problem.horizon, 1e-9);
}

// Removing the obstacle (by name, then the whole list by replace_all) replans the current goal
// for the world without it.
TEST_F(ReplanFixture, ObstacleRemovedReplans) {
  start_reach();
  const plan_t first = plan_goal(1, kGoal, 1);
  ASSERT_EQ(first.status, plan_t::SUCCESS);
  const Eigen::Vector3d tip = tip_at(first, 10);
  const Eigen::Vector3d pebble = tip + 0.05 * tip.normalized();
  send_obstacle("pebble", obstacle_t::ADD_OR_MOVE, kPebbleRadius, pebble);
  auto plans = listener_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  ASSERT_EQ(plans[1].status, plan_t::SUCCESS) << describe(plans[1]);
  EXPECT_TRUE(check(problem_with(kGoal, pebble), plans[1]).valid);

  send_obstacle("pebble", obstacle_t::REMOVE, kPebbleRadius, pebble);
  plans = listener_->wait_plans(3);
  ASSERT_EQ(plans.size(), 3u);
  EXPECT_EQ(plans[2].goal_id, 1);
  ASSERT_EQ(plans[2].status, plan_t::SUCCESS) << describe(plans[2]);
  EXPECT_EQ(plans[2].method, "incremental");
  EXPECT_TRUE(check(problem_with(kGoal), plans[2]).valid);
  // Without the pebble the previous plan is still feasible, so the replan (a descent from it)
  // costs no more.
  EXPECT_LE(plans[2].cost, plans[1].cost * 1.001);

  // replace_all with a new list: the pebble comes back under another name, the old name goes.
  send_obstacle("stone", obstacle_t::ADD_OR_MOVE, kPebbleRadius, pebble, /*replace_all=*/true);
  plans = listener_->wait_plans(4);
  ASSERT_EQ(plans.size(), 4u);
  ASSERT_EQ(plans[3].status, plan_t::SUCCESS) << describe(plans[3]);
  EXPECT_TRUE(check(problem_with(kGoal, pebble), plans[3]).valid);
  EXPECT_EQ(node_->counters().replans, 3);
}

// A measured state, then a goal: the plan starts where the robot is (incrementally re-anchored
// after a first plan).
TEST_F(ReplanFixture, MeasuredStateThenGoalStartsThere) {
  start_reach();
  ASSERT_EQ(plan_goal(1, kGoal, 1).status, plan_t::SUCCESS);
  robot_state_t state{};
  state.robot = "rr";
  state.num_joints = 2;
  state.joint_name = {"joint2", "joint1"};  // any order
  state.position = {0.05, -1.1};
  state.velocity = {0.0, 0.2};
  lcm_.publish("RR_STATE", &state);
  // A state alone does not replan; the next goal plans from it.
  const Eigen::Vector2d goal(1.1, 0.1);
  const plan_t p = plan_goal(2, goal, 2);
  ASSERT_EQ(p.status, plan_t::SUCCESS) << describe(p);
  EXPECT_EQ(p.method, "incremental");
  EXPECT_NEAR(p.q[0][0], -1.1, 1e-6);
  EXPECT_NEAR(p.q[0][1], 0.05, 1e-6);
  EXPECT_NEAR(p.qd[0][0], 0.2, 1e-6);
  EXPECT_NEAR(p.qd[0][1], 0.0, 1e-6);
  planning::Problem problem = problem_with(goal);
  problem.start_q = Eigen::Vector2d(-1.1, 0.05);
  problem.start_qd = Eigen::Vector2d(0.2, 0.0);
  EXPECT_TRUE(check(problem, p).valid);
}

// An invalid goal after a plan is answered INVALID_GOAL and leaves the planner able to replan
// the next goal incrementally.
TEST_F(ReplanFixture, InvalidGoalAfterAPlanKeepsServing) {
  start_reach();
  ASSERT_EQ(plan_goal(1, kGoal, 1).status, plan_t::SUCCESS);
  const plan_t bad = plan_goal(2, Eigen::Vector2d(10.0, 0.0), 2);  // beyond the joint limit
  EXPECT_EQ(bad.goal_id, 2);
  EXPECT_EQ(bad.status, plan_t::INVALID_GOAL) << describe(bad);
  const Eigen::Vector2d goal(1.1, 0.15);
  const plan_t next = plan_goal(3, goal, 3);
  EXPECT_EQ(next.goal_id, 3);
  ASSERT_EQ(next.status, plan_t::SUCCESS) << describe(next);
  EXPECT_EQ(next.method, "incremental");
  EXPECT_TRUE(check(problem_with(goal), next).valid);
}

// A replan that fails (here: no ISAM2 update allowed, no fallback, no retry) does not poison
// the next goal: it is planned from scratch and validates.
TEST_F(ReplanFixture, AFailedReplanIsFollowedByAPlanFromScratch) {
  PlannerNodeOptions options;
  options.replanning.incremental.max_updates = 0;
  options.replanning.fallback = false;
  options.replanning.retry_from_scratch = false;
  start_reach(options);
  ASSERT_EQ(plan_goal(1, kGoal, 1).status, plan_t::SUCCESS);
  const plan_t failed = plan_goal(2, Eigen::Vector2d(0.9, 0.5), 2);
  EXPECT_NE(failed.status, plan_t::SUCCESS);
  EXPECT_EQ(failed.method, "incremental");
  const Eigen::Vector2d goal(1.1, 0.1);
  const plan_t next = plan_goal(3, goal, 3);
  ASSERT_EQ(next.status, plan_t::SUCCESS) << describe(next);
  EXPECT_EQ(next.method, "batch");
  EXPECT_TRUE(check(problem_with(goal), next).valid);
}

// The same failing replan with the retry on: the request itself is planned again from scratch
// and answered with a valid plan.
TEST_F(ReplanFixture, AFailedReplanIsRetriedFromScratch) {
  PlannerNodeOptions options;
  options.replanning.incremental.max_updates = 0;
  options.replanning.fallback = false;
  start_reach(options);
  ASSERT_EQ(plan_goal(1, kGoal, 1).status, plan_t::SUCCESS);
  const Eigen::Vector2d goal(0.9, 0.5);
  const plan_t p = plan_goal(2, goal, 2);
  ASSERT_EQ(p.status, plan_t::SUCCESS) << describe(p);
  EXPECT_EQ(p.method, "batch after incremental");
  EXPECT_TRUE(check(problem_with(goal), p).valid);
  EXPECT_EQ(node_->counters().incremental, 1);
}

// With incremental replanning off, obstacle changes are warm-started batch solves and goals are
// planned from scratch (the node before iDFGP).
TEST_F(ReplanFixture, BatchModeWarmStartsObstacleReplans) {
  PlannerNodeOptions options;
  options.replanning.use_incremental = false;
  start_reach(options);
  const plan_t first = plan_goal(1, kGoal, 1);
  ASSERT_EQ(first.status, plan_t::SUCCESS);
  EXPECT_EQ(first.method, "batch");
  const Eigen::Vector3d tip = tip_at(first, 10);
  const Eigen::Vector3d pebble = tip + 0.05 * tip.normalized();
  send_obstacle("pebble", obstacle_t::ADD_OR_MOVE, kPebbleRadius, pebble);
  auto plans = listener_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  ASSERT_EQ(plans[1].status, plan_t::SUCCESS) << describe(plans[1]);
  EXPECT_TRUE(plans[1].method == "warm-start" || plans[1].method == "batch after warm-start")
      << plans[1].method;
  EXPECT_TRUE(check(problem_with(kGoal, pebble), plans[1]).valid);
  const plan_t next = plan_goal(2, Eigen::Vector2d(1.1, 0.1), 3);
  EXPECT_EQ(next.method, "batch");
  EXPECT_EQ(node_->counters().incremental, 0);
}

// The node's batch solves are in the formulation of PlannerNodeOptions::replanning. The plan tells:
// condensed torques are RNEA of the trajectory (no dynamics residual), the DFG's are its own τ
// variables, which meet the equations of motion to the solver's tolerance only.
TEST_F(ReplanFixture, BatchSolvesAreCondensedByDefault) {
  PlannerNodeOptions options;
  options.replanning.use_incremental = false;
  start_reach(options);
  const plan_t p = plan_goal(1, kGoal, 1);
  ASSERT_EQ(p.status, plan_t::SUCCESS) << describe(p);
  EXPECT_LT(p.max_dynamics_residual, 1e-9);
}

TEST_F(ReplanFixture, BatchSolvesAreInTheDfgFormulationWhenAsked) {
  PlannerNodeOptions options;
  options.replanning.use_incremental = false;
  options.replanning.incremental.batch.formulation = planning::Formulation::kDynamicFactorGraph;
  start_reach(options);
  const plan_t p = plan_goal(1, kGoal, 1);
  ASSERT_EQ(p.status, plan_t::SUCCESS) << describe(p);
  EXPECT_EQ(p.method, "batch");
  EXPECT_GT(p.max_dynamics_residual, 1e-9);
  EXPECT_TRUE(check(problem_with(kGoal), p).valid);
}

// An obstacle with a NaN coordinate is rejected (a status says why) and triggers no replan.
TEST_F(ReplanFixture, NaNObstacleIsRejectedWithoutReplanning) {
  start_reach();
  ASSERT_EQ(plan_goal(1, kGoal, 1).status, plan_t::SUCCESS);
  send_obstacle("pebble", obstacle_t::ADD_OR_MOVE, kPebbleRadius, {0.0, std::nan(""), 1.0});
  EXPECT_TRUE(listener_->wait_status_containing("non-finite size or position"));
  // The next goal is still planned, incrementally, in the world without the pebble.
  const Eigen::Vector2d goal(1.1, 0.1);
  const plan_t p = plan_goal(2, goal, 2);
  ASSERT_EQ(p.status, plan_t::SUCCESS) << describe(p);
  EXPECT_EQ(p.method, "incremental");
  const NodeCounters c = node_->counters();
  EXPECT_EQ(c.messages_rejected, 1);
  EXPECT_EQ(c.replans, 0);
}

// The box of side 1e80 m around the robot that Bullet measured as no collision: refused with a
// reason, and the next goal is planned in the world without it.
TEST_F(ReplanFixture, AnAbsurdlyLargeObstacleIsRefused) {
  start_reach();
  ASSERT_EQ(plan_goal(1, kGoal, 1).status, plan_t::SUCCESS);
  obstacle_list_t list{};
  obstacle_t o{};
  o.id = "room";
  o.action = obstacle_t::ADD_OR_MOVE;
  o.shape = obstacle_t::BOX;
  o.size[0] = o.size[1] = o.size[2] = 1e80;
  o.quaternion[0] = 1;
  list.obstacles = {o};
  list.num_obstacles = 1;
  lcm_.publish("RR_OBSTACLES", &list);
  EXPECT_TRUE(listener_->wait_status_containing("(\"room\").size: box side x is 1e+80 m"));
  const plan_t p = plan_goal(2, Eigen::Vector2d(1.1, 0.1), 2);
  ASSERT_EQ(p.status, plan_t::SUCCESS) << describe(p);
  EXPECT_EQ(node_->counters().replans, 0);
}

// Obstacles beyond the world's bound are not added (each named in the status); moves of known
// ones still are.
TEST_F(NodeFixture, TheWorldHoldsAtMostTheDocumentedNumberOfObstacles) {
  auto batch = [](int first, int count) {
    obstacle_list_t list{};
    for (int i = first; i < first + count; ++i) {
      obstacle_t o{};
      o.id = "pebble" + std::to_string(i);
      o.action = obstacle_t::ADD_OR_MOVE;
      o.shape = obstacle_t::SPHERE;
      o.size[0] = 0.01;
      o.position[0] = 5.0 + 0.02 * (i % 50);
      o.position[1] = 0.02 * (i / 50);
      o.quaternion[0] = 1;
      list.obstacles.push_back(o);
    }
    list.num_obstacles = static_cast<int32_t>(list.obstacles.size());
    return list;
  };
  for (int first = 0; first < collision::kMaxObstacles + 10;
       first += messages::kMaxObstaclesPerMessage) {
    const obstacle_list_t list = batch(first, messages::kMaxObstaclesPerMessage);
    lcm_.publish("RR_OBSTACLES", &list);
  }
  EXPECT_TRUE(listener_->wait_status_containing(
      "obstacle \"pebble1024\" and 255 more not added: the world holds the most obstacles it "
      "may, 1024"));
}

}  // namespace
}  // namespace kinograph::daemon

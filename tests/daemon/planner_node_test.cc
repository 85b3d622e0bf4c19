// The daemon's node end to end over an in-process memq:// LCM: goals are answered by plans,
// malformed and invalid messages by statuses, obstacle changes trigger replans, and the newest
// goal wins. Real planning on the RR arm; no network.
#include "daemon/planner_node.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <set>
#include <thread>

#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planner_status_t.hpp"
#include "lcmtypes/safe_decode.h"

namespace kinograph::daemon {
namespace {

constexpr char kScene[] = R"(
name: rr_daemon_test
robot:
  urdf: robots/rr/rr.urdf
horizon: 2.0
steps: 30
start:
  q: [-0.8, 0.4]
goal:
  q: [0.8, -0.4]
)";

// Records what the node publishes, from the node's LCM thread, for the test thread to wait on.
class Listener {
 public:
  explicit Listener(lcm::LCM& lcm) {
    lcm.subscribe("RR_PLAN", &Listener::on_plan, this);
    lcm.subscribe("RR_PLANNER_STATUS", &Listener::on_status, this);
  }
  void on_plan(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    plan_t msg;
    ASSERT_TRUE(lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg).ok);
    std::lock_guard lock(mutex_);
    plans_.push_back(std::move(msg));
    cv_.notify_all();
  }
  void on_status(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    planner_status_t msg;
    ASSERT_TRUE(lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg).ok);
    std::lock_guard lock(mutex_);
    statuses_.push_back(std::move(msg));
    cv_.notify_all();
  }
  // Waits (bounded) until `count` plans have arrived; returns a copy of all of them.
  std::vector<plan_t> wait_plans(size_t count, double timeout_s = 60) {
    std::unique_lock lock(mutex_);
    cv_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                 [&] { return plans_.size() >= count; });
    return plans_;
  }
  // Waits until some status message mentions `text`.
  bool wait_status_containing(const std::string& text, double timeout_s = 10) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] {
      for (const auto& s : statuses_) {
        if (s.message.find(text) != std::string::npos) return true;
      }
      return false;
    });
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<plan_t> plans_;
  std::vector<planner_status_t> statuses_;
};

// A node running on its own thread over one shared memq:// instance.
class NodeFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(lcm_.good());
    auto scene = planning::parse_scene(kScene, std::string(KINOGRAPH_SOURCE_DIR) + "/scene.yaml");
    PlannerNodeOptions options;
    options.channel_prefix = "RR";
    options.status_period_s = 0.2;
    node_ = std::make_unique<PlannerNode>(std::move(scene), options, &lcm_);
    listener_ = std::make_unique<Listener>(lcm_);
    thread_ = std::thread([this] { node_->run(stop_); });
  }
  void TearDown() override {
    stop_ = true;
    thread_.join();
  }
  void send_goal(int64_t id, std::vector<double> q) {
    goal_t g{};
    g.goal_id = id;
    g.kind = goal_t::KIND_JOINT_CONFIGURATION;
    g.num_joints = static_cast<int32_t>(q.size());
    g.joint_position = std::move(q);
    g.ee_quaternion[0] = 1;
    lcm_.publish("RR_GOAL", &g);
  }

  lcm::LCM lcm_{"memq://"};
  std::atomic<bool> stop_{false};
  std::unique_ptr<PlannerNode> node_;
  std::unique_ptr<Listener> listener_;
  std::thread thread_;
};

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

TEST_F(NodeFixture, NewestGoalWinsAndEveryGoalIsAnswered) {
  for (int i = 0; i < 4; ++i) send_goal(20 + i, {0.2 * i, 0.1});
  // Each goal gets exactly one answer: planned, or cancelled because a newer one came first.
  auto plans = listener_->wait_plans(4);
  ASSERT_EQ(plans.size(), 4u);
  std::set<int64_t> answered;
  for (const auto& p : plans) {
    EXPECT_TRUE(answered.insert(p.goal_id).second) << "goal " << p.goal_id << " answered twice";
    EXPECT_TRUE(p.status == plan_t::SUCCESS || p.status == plan_t::CANCELLED);
  }
  EXPECT_EQ(answered, (std::set<int64_t>{20, 21, 22, 23}));
  const auto newest =
      std::find_if(plans.begin(), plans.end(), [](const plan_t& p) { return p.goal_id == 23; });
  EXPECT_EQ(newest->status, plan_t::SUCCESS);
}

}  // namespace
}  // namespace kinograph::daemon

// A daemon with a neighbour and no measured states, end to end over an in-process memq:// LCM: its
// first plan starts at the scene's start, and every later one where its plans in force have the
// robot at the new plan's start (q and q̇ on the common clock), never back at the scene's start;
// it yields to the neighbour's plan in the making. Real planning on the RR arm; the neighbour is
// a far-away RR arm whose plans and heartbeats the test publishes.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <lcm/lcm-cpp.hpp>
#include <thread>

#include "daemon/planner_node.h"
#include "kinograph/fleet/joint_clearance.h"
#include "kinograph/fleet/model_id.h"
#include "kinograph/lcm/message_convert.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/trajectory_sampler.h"
#include "kinograph/planning/validate.h"
#include "tests/daemon/node_listener.h"
#include "tests/daemon/rr_scene.h"

namespace kinograph::daemon {
namespace {

// Far enough away never to be in the way: only its plans' arrival matters here.
constexpr char kFarScene[] = R"(
name: rr_fleet_far
robot:
  urdf: robots/rr/rr.urdf
  base: {position: [6, 0, 0]}
horizon: 2.0
steps: 30
start:
  q: [0, 0]
goal:
  q: [0, 0]
)";

int64_t wall_utime() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

class NeighbourNodeTest : public ::testing::Test {
 protected:
  // Starts the node; `yield_s` is its PlannerNodeOptions::neighbour_yield_s.
  void start(double yield_s = 5.0) {
    ASSERT_TRUE(lcm_.good());
    const std::string anchor = std::string(KINOGRAPH_SOURCE_DIR) + "/scene.yaml";
    own_ = testing::rr_daemon_scene();
    const planning::Scene far = planning::parse_scene(kFarScene, anchor);
    far_.name = "far";
    far_.channel_prefix = "FAR";
    far_.model = far.problem.model;
    far_.base = far.base;
    far_.start_q = far.problem.start_q;
    PlannerNodeOptions options;
    options.channel_prefix = "RR";
    options.status_period_s = 0.2;
    options.neighbours = {far_};
    options.neighbour_watch.timeout_s = 600;  // never silent while the test waits
    options.neighbour_yield_s = yield_s;
    node_ = std::make_unique<PlannerNode>(own_, options, &lcm_);
    listener_ = std::make_unique<Listener>(lcm_);
    thread_ = std::thread([this] { node_->run(stop_); });
  }
  void TearDown() override {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  // The far arm's heartbeat: its goal at 1 s outranks this robot's (at 2 s); with
  // `planning_goal_utime` it says it is making a plan for a goal of that utime.
  void send_far_heartbeat(int64_t planning_goal_utime = -1) {
    planner_status_t m;
    m.robot = far_.model->name;
    m.model_id = fleet::model_id(*far_.model);
    for (int i = 0; i < 3; ++i) m.base_position[i] = far_.base.translation()[i];
    m.base_quaternion[0] = 1;
    m.goal_utime = 1'000'000;
    m.planning_goal_utime = planning_goal_utime;
    lcm_.publish("FAR_PLANNER_STATUS", &m);
  }
  // A new plan of the far arm, standing still from now on: the rule's cue to replan.
  void send_far_plan(int64_t plan_id) {
    messages::PlanTime time;
    time.start_utime = time.takeover_utime = time.utime = wall_utime();
    planning::Plan p = fleet::standing_plan(far_.start_q);
    p.validation.valid = true;
    const plan_t m = messages::plan_to_message(p, *far_.model, far_.model->name, plan_id, 1, time);
    lcm_.publish("FAR_PLAN", &m);
  }
  void send_goal() {
    goal_t g{};
    g.utime = 2'000'000;
    g.goal_id = 1;
    g.kind = goal_t::KIND_JOINT_CONFIGURATION;
    g.num_joints = 2;
    g.joint_position = {0.8, -0.4};
    g.ee_quaternion[0] = 1;
    lcm_.publish("RR_GOAL", &g);
  }
  // Where `earlier` has the robot at `later`'s start on the common clock.
  planning::InterpolantPoint where(const plan_t& earlier, const plan_t& later) const {
    const planning::Plan p = messages::plan_from_message(earlier);
    planning::TrajectorySampler sampler(*own_.problem.model, p);
    return sampler.at(static_cast<double>(later.start_utime - earlier.start_utime) * 1e-6);
  }
  // The own scene's problem started where `plan` starts: what a replan must validate against.
  planning::Validation validate_from_its_start(const plan_t& plan) const {
    const planning::Plan p = messages::plan_from_message(plan);
    planning::Problem problem = own_.problem;
    problem.start_q = p.q.row(0).transpose();
    problem.start_qd = p.qd.row(0).transpose();
    return planning::validate(problem, p);
  }
  static Eigen::Vector2d at(const std::vector<std::vector<double>>& rows, std::size_t k) {
    return {rows[k][0], rows[k][1]};
  }

  lcm::LCM lcm_{"memq://"};
  planning::Scene own_;
  NeighbourSpec far_;
  std::atomic<bool> stop_{false};
  std::unique_ptr<PlannerNode> node_;
  std::unique_ptr<Listener> listener_;
  std::thread thread_;
};

TEST_F(NeighbourNodeTest, WithoutStatesALaterPlanStartsWhereTheOwnPlanInForceHasTheRobot) {
  start();
  send_far_heartbeat();
  send_goal();
  std::vector<plan_t> plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  const plan_t first = plans[0];
  ASSERT_EQ(first.status, plan_t::SUCCESS) << first.status_message;
  EXPECT_EQ(first.state_utime, -1);
  EXPECT_LE((at(first.q, 0) - own_.problem.start_q).cwiseAbs().maxCoeff(), 1e-9);

  // The higher neighbour's new plan, while the first is under way: the replan continues it.
  send_far_plan(1);
  plans = listener_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  const plan_t second = plans[1];
  ASSERT_EQ(second.status, plan_t::SUCCESS) << second.status_message;
  ASSERT_GT(second.start_utime, first.start_utime);
  const planning::InterpolantPoint then = where(first, second);
  EXPECT_LE((at(second.q, 0) - then.q).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LE((at(second.qd, 0) - then.qd).cwiseAbs().maxCoeff(), 1e-6);
  planning::Validation v = validate_from_its_start(second);
  EXPECT_TRUE(v.valid) << (v.failures.empty() ? "" : v.failures.front());

  // Once that plan has ended on the common clock, the robot is at its goal, at rest: the next
  // replan starts there, not back at the scene's start.
  std::this_thread::sleep_until(
      std::chrono::system_clock::time_point(std::chrono::microseconds(second.start_utime)) +
      std::chrono::duration<double>(second.t.back()));
  send_far_plan(2);
  plans = listener_->wait_plans(3);
  ASSERT_EQ(plans.size(), 3u);
  const plan_t third = plans[2];
  ASSERT_EQ(third.status, plan_t::SUCCESS) << third.status_message;
  EXPECT_LE((at(third.q, 0) - at(second.q, second.q.size() - 1)).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LE(at(third.qd, 0).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_GT((at(third.q, 0) - own_.problem.start_q).cwiseAbs().maxCoeff(), 0.5);
  v = validate_from_its_start(third);
  EXPECT_TRUE(v.valid) << (v.failures.empty() ? "" : v.failures.front());
  EXPECT_EQ(node_->counters().neighbour_replans, 2);
}

// The neighbour is making a plan for an earlier goal: the robot announces its own plan in the
// making at once, waits, and plans only when the neighbour's heartbeat says it is done.
TEST_F(NeighbourNodeTest, YieldsToAHigherNeighboursPlanInTheMakingUntilItIsDone) {
  start();
  send_far_heartbeat(/*planning_goal_utime=*/1'000'000);
  send_goal();
  EXPECT_TRUE(listener_->wait_status_planning(2'000'000));
  // The yield lasts up to 5 s: no plan can come within the first half second.
  EXPECT_TRUE(listener_->wait_plans(1, 0.5).empty());
  send_far_plan(1);
  send_far_heartbeat();
  const std::vector<plan_t> plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].status, plan_t::SUCCESS) << plans[0].status_message;
  EXPECT_EQ(node_->counters().neighbour_yields, 1);
  EXPECT_EQ(node_->counters().neighbour_replans, 0);  // made around the plan that just came
}

// A neighbour that never finishes its plan holds the robot up for the yield's bound only.
TEST_F(NeighbourNodeTest, PlansAnywayOnceTheYieldsBoundHasPassed) {
  start(/*yield_s=*/0.3);
  send_far_heartbeat(/*planning_goal_utime=*/1'000'000);
  const auto sent = std::chrono::steady_clock::now();
  send_goal();
  const std::vector<plan_t> plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_GE(std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count(), 0.3);
  EXPECT_EQ(plans[0].status, plan_t::SUCCESS) << plans[0].status_message;
  EXPECT_EQ(node_->counters().neighbour_yields, 1);
}

// With yielding off, a neighbour's plan in the making does not hold the robot up.
TEST_F(NeighbourNodeTest, DoesNotYieldWithYieldingOff) {
  start(/*yield_s=*/0);
  send_far_heartbeat(/*planning_goal_utime=*/1'000'000);
  send_goal();
  const std::vector<plan_t> plans = listener_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].status, plan_t::SUCCESS) << plans[0].status_message;
  EXPECT_EQ(node_->counters().neighbour_yields, 0);
}

}  // namespace
}  // namespace kinograph::daemon

// Checks of LCM messages from the network: every malformed field is rejected with a reason
// that names it, and good messages convert exactly.
#include "kinograph/lcm/message_convert.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace kinograph::messages {
namespace {

const dynamics::Model& rr() {
  static const dynamics::Model model =
      dynamics::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/rr/rr.urdf");
  return model;
}

RobotIdentity identity() { return {rr().name, "RR"}; }

goal_t joint_goal(std::vector<double> q) {
  goal_t g{};
  g.goal_id = 7;
  g.robot = "RR";
  g.kind = goal_t::KIND_JOINT_CONFIGURATION;
  g.num_joints = static_cast<int32_t>(q.size());
  g.joint_position = std::move(q);
  g.ee_quaternion[0] = 1;
  return g;
}

TEST(GoalFromMessage, ConvertsJointGoal) {
  GoalRequest out;
  Check c = goal_from_message(joint_goal({0.5, -0.25}), rr(), identity(), out);
  ASSERT_TRUE(c.ok) << c.reason;
  EXPECT_EQ(out.goal_id, 7);
  EXPECT_EQ(out.goal.kind, planning::Goal::Kind::kJoint);
  EXPECT_DOUBLE_EQ(out.goal.q[0], 0.5);
  EXPECT_DOUBLE_EQ(out.goal.q[1], -0.25);
}

TEST(GoalFromMessage, RejectsWrongJointCountNaNRobotKindAndDuration) {
  GoalRequest out;
  Check c = goal_from_message(joint_goal({0.5}), rr(), identity(), out);
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.reason.find("num_joints"), std::string::npos) << c.reason;

  c = goal_from_message(joint_goal({0.5, std::nan("")}), rr(), identity(), out);
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.reason.find("joint_position"), std::string::npos) << c.reason;

  goal_t g = joint_goal({0, 0});
  g.robot = "IIWA";
  c = goal_from_message(g, rr(), identity(), out);
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.reason.find("robot"), std::string::npos) << c.reason;

  g = joint_goal({0, 0});
  g.kind = 9;
  EXPECT_FALSE(goal_from_message(g, rr(), identity(), out).ok);

  g = joint_goal({0, 0});
  g.duration_s = -1;
  EXPECT_FALSE(goal_from_message(g, rr(), identity(), out).ok);
  g.duration_s = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(goal_from_message(g, rr(), identity(), out).ok);
}

TEST(GoalFromMessage, PoseGoalNeedsKnownFrameAndUnitQuaternion) {
  goal_t g = joint_goal({});
  g.kind = goal_t::KIND_END_EFFECTOR_POSE;
  g.ee_frame = "ee";
  g.ee_position[0] = 0.5;
  g.ee_position[2] = 1.0;
  GoalRequest out;
  Check c = goal_from_message(g, rr(), identity(), out);
  ASSERT_TRUE(c.ok) << c.reason;
  EXPECT_EQ(out.goal.frame, "ee");
  EXPECT_NEAR(out.goal.pose.translation().z(), 1.0, 1e-15);

  g.ee_frame = "no_such_frame";
  c = goal_from_message(g, rr(), identity(), out);
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.reason.find("no_such_frame"), std::string::npos);

  g.ee_frame = "ee";
  g.ee_quaternion[0] = 2;
  c = goal_from_message(g, rr(), identity(), out);
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.reason.find("unit quaternion"), std::string::npos) << c.reason;
}

obstacle_t box(const std::string& id) {
  obstacle_t o{};
  o.id = id;
  o.action = obstacle_t::ADD_OR_MOVE;
  o.shape = obstacle_t::BOX;
  o.size[0] = o.size[1] = o.size[2] = 0.2;
  o.position[0] = 1;
  o.quaternion[0] = 1;
  return o;
}

TEST(ObstaclesFromMessage, ConvertsAndRejectsBadShapes) {
  obstacle_list_t msg{};
  msg.obstacles = {box("a"), box("b")};
  msg.obstacles[1].action = obstacle_t::REMOVE;
  msg.num_obstacles = 2;
  std::vector<ObstacleUpdate> out;
  Check c = obstacles_from_message(msg, out);
  ASSERT_TRUE(c.ok) << c.reason;
  ASSERT_EQ(out.size(), 2u);
  EXPECT_FALSE(out[0].remove);
  EXPECT_DOUBLE_EQ(out[0].pose.translation().x(), 1.0);
  EXPECT_TRUE(out[1].remove);

  for (auto mutate : std::vector<std::function<void(obstacle_t&)>>{
           [](obstacle_t& o) { o.size[1] = -1; },
           [](obstacle_t& o) { o.position[2] = std::nan(""); }, [](obstacle_t& o) { o.shape = 42; },
           [](obstacle_t& o) { o.action = 3; }, [](obstacle_t& o) { o.id.clear(); },
           [](obstacle_t& o) { o.quaternion[0] = 0; }}) {
    obstacle_list_t bad{};
    bad.obstacles = {box("a")};
    mutate(bad.obstacles[0]);
    bad.num_obstacles = 1;
    std::vector<ObstacleUpdate> none;
    Check r = obstacles_from_message(bad, none);
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.reason.find("obstacles[0]"), std::string::npos) << r.reason;
    EXPECT_TRUE(none.empty());
  }
}

// A shape or position the collision engine cannot measure faithfully is refused, naming the
// obstacle, the dimension and the limit (a 1e80 m box around the robot read as no collision).
TEST(ObstaclesFromMessage, RefusesShapesAndPositionsBeyondTheFaithfulRange) {
  struct Case {
    int8_t shape;
    double size[3];
    double position_x;
    std::string names;
  };
  const std::vector<Case> cases = {
      {obstacle_t::BOX,
       {1e80, 1e80, 1e80},
       0,
       "(\"a\").size: box side x is 1e+80 m, beyond the 10000 m"},
      {obstacle_t::CYLINDER, {1e79, 1, 0}, 0, "cylinder radius is 1e+79 m, beyond the 10 m"},
      {obstacle_t::CYLINDER, {1, 11, 0}, 0, "cylinder length is 11 m"},
      {obstacle_t::SPHERE, {5e-5, 0, 0}, 0, "sphere radius is 5e-05 m, below the 0.0001 m"},
      {obstacle_t::CAPSULE, {2e4, 1, 0}, 0, "capsule radius is 20000 m"},
      {obstacle_t::BOX, {0.2, 0.2, 0.2}, 2e5, "(\"a\"): position x is 200000 m, beyond the"},
  };
  for (const Case& c : cases) {
    obstacle_list_t msg{};
    msg.obstacles = {box("a")};
    msg.obstacles[0].shape = c.shape;
    for (int i = 0; i < 3; ++i) msg.obstacles[0].size[i] = c.size[i];
    msg.obstacles[0].position[0] = c.position_x;
    msg.num_obstacles = 1;
    std::vector<ObstacleUpdate> out;
    const Check r = obstacles_from_message(msg, out);
    EXPECT_FALSE(r.ok) << c.names;
    EXPECT_NE(r.reason.find(c.names), std::string::npos) << r.reason;
    EXPECT_TRUE(out.empty());
  }
  // The ends of the ranges are accepted.
  obstacle_list_t edge{};
  edge.obstacles = {box("floor"), box("can")};
  edge.obstacles[0].size[0] = edge.obstacles[0].size[1] = 1e4;
  edge.obstacles[1].shape = obstacle_t::CYLINDER;
  edge.obstacles[1].size[0] = edge.obstacles[1].size[1] = 10;
  edge.obstacles[1].position[0] = -1e5;
  edge.num_obstacles = 2;
  std::vector<ObstacleUpdate> out;
  const Check r = obstacles_from_message(edge, out);
  EXPECT_TRUE(r.ok) << r.reason;
  EXPECT_EQ(out.size(), 2u);
}

TEST(ObstaclesFromMessage, RefusesMoreObstaclesThanOneMessageMayCarry) {
  obstacle_list_t msg{};
  msg.obstacles.assign(kMaxObstaclesPerMessage, box("x"));
  msg.num_obstacles = kMaxObstaclesPerMessage;
  std::vector<ObstacleUpdate> out;
  EXPECT_TRUE(obstacles_from_message(msg, out).ok);
  EXPECT_EQ(out.size(), static_cast<size_t>(kMaxObstaclesPerMessage));
  msg.obstacles.push_back(box("y"));
  msg.num_obstacles = kMaxObstaclesPerMessage + 1;
  std::vector<ObstacleUpdate> none;
  const Check r = obstacles_from_message(msg, none);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("num_obstacles is 257, more than the 256"), std::string::npos)
      << r.reason;
  EXPECT_TRUE(none.empty());
}

TEST(StateFromMessage, ReordersByJointNameAndRejectsUnknownNames) {
  robot_state_t s{};
  s.robot = rr().name;
  s.num_joints = 2;
  s.joint_name = {rr().bodies[1].joint_name, rr().bodies[0].joint_name};
  s.position = {0.2, 0.1};
  s.velocity = {-2, -1};
  MeasuredState out;
  Check c = state_from_message(s, rr(), identity(), out);
  ASSERT_TRUE(c.ok) << c.reason;
  EXPECT_DOUBLE_EQ(out.q[0], 0.1);
  EXPECT_DOUBLE_EQ(out.q[1], 0.2);
  EXPECT_DOUBLE_EQ(out.qd[0], -1);

  s.joint_name[0] = "elbowz";
  c = state_from_message(s, rr(), identity(), out);
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.reason.find("elbowz"), std::string::npos);

  s.joint_name = {rr().bodies[0].joint_name, rr().bodies[0].joint_name};
  EXPECT_FALSE(state_from_message(s, rr(), identity(), out).ok);
}

TEST(PlanMessage, RoundTripsTrajectoryAndMapsStatus) {
  planning::Plan plan;
  plan.t = {0, 0.5, 1};
  plan.q = Eigen::MatrixXd::Random(3, 2);
  plan.qd = Eigen::MatrixXd::Random(3, 2);
  plan.qdd = Eigen::MatrixXd::Random(3, 2);
  plan.tau = Eigen::MatrixXd::Random(3, 2);
  plan.validation.valid = true;
  plan.stats.method = "batch-L";
  plan_t msg = plan_to_message(plan, rr(), "rr", 3, 7, {});
  EXPECT_EQ(msg.status, plan_t::SUCCESS);
  EXPECT_EQ(msg.num_steps, 3);
  EXPECT_EQ(msg.joint_name.size(), 2u);
  planning::Plan back = plan_from_message(msg);
  EXPECT_TRUE(back.q.isApprox(plan.q));
  EXPECT_TRUE(back.tau.isApprox(plan.tau));
  EXPECT_EQ(back.t, plan.t);

  plan.validation.valid = false;
  plan.validation.failures = {"collision at step 4"};
  msg = plan_to_message(plan, rr(), "rr", 4, 7, {});
  EXPECT_EQ(msg.status, plan_t::NOT_CONVERGED);
  EXPECT_NE(msg.status_message.find("collision at step 4"), std::string::npos);

  plan.stats.status = planning::PlanStatus::kInvalidProblem;
  EXPECT_EQ(plan_to_message(plan, rr(), "rr", 5, 7, {}).status, plan_t::INVALID_GOAL);
}

}  // namespace
}  // namespace kinograph::messages

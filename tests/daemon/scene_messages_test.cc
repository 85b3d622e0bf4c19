// What a scene file can say, said over LCM to a running node (memq://): a payload attached to
// and detached from a link, goal tolerances, and mesh obstacles by file. Each plan is checked
// against the problem a scene file saying the same would give. Real planning on the RR arm.
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <thread>

#include "daemon/planner_node.h"
#include "kinograph/goal_v3_t.hpp"
#include "kinograph/lcm/message_convert.h"
#include "kinograph/mesh_obstacle_list_t.hpp"
#include "kinograph/payload_t.hpp"
#include "kinograph/planner_status_t.hpp"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/validate.h"
#include "lcmtypes/safe_decode.h"
#include "tests/daemon/node_listener.h"

namespace kinograph::daemon {
namespace {

namespace fs = std::filesystem;

// The RR arm swings over the top from (-0.8, 0.4) to (0.8, -0.4); `extra` is appended to the
// scene (obstacles, payload).
std::string rr_scene(const std::string& robot_extra = "", const std::string& extra = "") {
  return "name: rr_scene_messages\nrobot:\n  urdf: " + std::string(KINOGRAPH_SOURCE_DIR) +
         "/robots/rr/rr.urdf\n" + robot_extra +
         "horizon: 2.0\nsteps: 30\nstart:\n  q: [-0.8, 0.4]\ngoal:\n  q: [0.8, -0.4]\n" + extra;
}

// A box payload at the tip that sticks 0.15..0.45 m out of the arm's plane (+y), as a scene's
// robot.payload says it.
constexpr char kPayloadYaml[] =
    "  payload: {frame: ee, mass: 1.0, size: [0.1, 0.3, 0.1], offset: [0, 0.3, 0]}\n";
// A ball beside the top of the swing, out of the plane: the bare arm passes 0.15 m from it,
// the payload through it.
constexpr char kBallYaml[] =
    "obstacles:\n  - {id: ball, shape: sphere, size: [0.1], position: [0, 0.3, 1.8]}\n";

class SceneMessages : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/kinograph_scene_messages_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    fs::remove_all(dir_);
  }
  // Starts a node on `yaml`, read as the file scene.yaml in the test's directory.
  void start(const std::string& yaml) {
    ASSERT_TRUE(lcm_.good());
    PlannerNodeOptions options;
    options.channel_prefix = "RR";
    options.status_period_s = 0.2;
    node_ = std::make_unique<PlannerNode>(planning::parse_scene(yaml, scene_path()), options, &lcm_);
    answers_ = std::make_unique<Listener>(lcm_);
    thread_ = std::thread([this] { node_->run(stop_); });
  }
  std::string scene_path() const { return dir_ + "/scene.yaml"; }
  // Validates a received plan against the problem of a scene file.
  planning::Validation validate_against(const std::string& yaml, const plan_t& msg) const {
    const planning::Scene scene = planning::parse_scene(yaml, scene_path());
    return planning::validate(scene.problem, messages::plan_from_message(msg));
  }
  void send_goal(int64_t id, std::vector<double> q, std::vector<double> tolerance = {0, 0}) {
    goal_v3_t g{};
    g.goal_id = id;
    g.kind = goal_v3_t::KIND_JOINT_CONFIGURATION;
    g.joint_name = {"joint1", "joint2"};
    g.joint_position = std::move(q);
    g.joint_tolerance = std::move(tolerance);
    g.num_joints = 2;
    g.ee_quaternion[0] = 1;
    lcm_.publish("RR_GOAL", &g);
  }
  void send_payload(int8_t action) {
    payload_t p{};
    p.action = action;
    p.frame = "ee";
    p.mass_kg = 1.0;
    p.size[0] = 0.1;
    p.size[1] = 0.3;
    p.size[2] = 0.1;
    p.offset[1] = 0.3;
    lcm_.publish("RR_PAYLOAD", &p);
  }
  void send_mesh(const std::string& id, const std::string& mesh, const Eigen::Vector3d& position) {
    mesh_obstacle_list_t list{};
    mesh_obstacle_t o{};
    o.id = id;
    o.action = mesh_obstacle_t::ADD_OR_MOVE;
    o.mesh = mesh;
    o.scale[0] = o.scale[1] = o.scale[2] = 1;
    for (int i = 0; i < 3; ++i) o.position[i] = position[i];
    o.quaternion[0] = 1;
    list.obstacles = {o};
    list.num_obstacles = 1;
    lcm_.publish("RR_OBSTACLES", &list);
  }
  // An OBJ file of an axis-aligned box with full extents `size` about its origin.
  std::string write_box_obj(const std::string& name, const Eigen::Vector3d& size) const {
    const std::string path = dir_ + "/" + name;
    std::ofstream out(path);
    for (int i = 0; i < 8; ++i) {
      out << "v " << (i & 1 ? 0.5 : -0.5) * size.x() << " " << (i & 2 ? 0.5 : -0.5) * size.y()
          << " " << (i & 4 ? 0.5 : -0.5) * size.z() << "\n";
    }
    out << "f 1 2 4 3\nf 5 6 8 7\nf 1 2 6 5\nf 3 4 8 7\nf 1 3 7 5\nf 2 4 8 6\n";
    return path;
  }

  lcm::LCM lcm_{"memq://"};
  std::string dir_;
  std::atomic<bool> stop_{false};
  std::unique_ptr<PlannerNode> node_;
  std::unique_ptr<Listener> answers_;
  std::thread thread_;
};

// Attached over LCM, the payload is the robot's for the next plan: the plan validates against
// the scene that carries it (its dynamics and the payload's clearance from the ball) and not
// against the bare arm's dynamics. Detached, the next plan is the bare arm's again.
TEST_F(SceneMessages, AnAttachedPayloadIsPlannedForAndADetachedOneIsNot) {
  start(rr_scene("", kBallYaml));
  const std::string with_payload = rr_scene(kPayloadYaml, kBallYaml);
  const std::string bare = rr_scene("", kBallYaml);
  send_payload(payload_t::ATTACH);
  send_goal(1, {0.8, -0.4});
  auto plans = answers_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  ASSERT_EQ(plans[0].status, plan_t::SUCCESS) << plans[0].status_message;
  const planning::Validation carried = validate_against(with_payload, plans[0]);
  EXPECT_TRUE(carried.valid) << carried.failures.front();
  EXPECT_GE(carried.min_clearance, 0.0);
  const planning::Validation as_bare = validate_against(bare, plans[0]);
  EXPECT_FALSE(as_bare.valid);
  EXPECT_GT(as_bare.max_dynamics_residual, 1.0);  // the payload's 1 kg at the tip: ~8 N m
  EXPECT_EQ(node_->counters().payload_changes, 1);

  send_payload(payload_t::DETACH);
  send_goal(2, {0.8, -0.4});
  plans = answers_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  ASSERT_EQ(plans[1].status, plan_t::SUCCESS) << plans[1].status_message;
  const planning::Validation detached = validate_against(bare, plans[1]);
  EXPECT_TRUE(detached.valid) << detached.failures.front();
  EXPECT_FALSE(validate_against(with_payload, plans[1]).valid);
}

// Without the payload the straight swing is clear of the ball; the payload would hit it there:
// the attached plan's detour is the payload's, checked above, and the ball matters.
TEST_F(SceneMessages, ThePayloadWouldHitTheBallOnTheBareArmsPath) {
  start(rr_scene("", kBallYaml));
  send_goal(1, {0.8, -0.4});
  const auto plans = answers_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  ASSERT_EQ(plans[0].status, plan_t::SUCCESS) << plans[0].status_message;
  const planning::Validation v = validate_against(rr_scene(kPayloadYaml, kBallYaml), plans[0]);
  EXPECT_LT(v.min_clearance, 0.0);
}

TEST_F(SceneMessages, ABadPayloadIsRefusedNamingTheField) {
  start(rr_scene());
  payload_t p{};
  p.action = payload_t::ATTACH;
  p.frame = "gripper";
  p.size[0] = p.size[1] = p.size[2] = 0.1;
  lcm_.publish("RR_PAYLOAD", &p);
  EXPECT_TRUE(answers_->wait_status_containing("payload_t.frame \"gripper\" is not a frame of rr"));
  p.frame = "ee";
  p.size[1] = -0.1;
  lcm_.publish("RR_PAYLOAD", &p);
  EXPECT_TRUE(answers_->wait_status_containing("payload_t.size must be > 0"));
  EXPECT_EQ(node_->counters().payload_changes, 0);
}

// A tolerance 100 times tighter than the default is met; one joint's looser tolerance lets a
// farther end pass; a negative one is refused naming the joint.
TEST_F(SceneMessages, GoalTolerancesAreHonoured) {
  start(rr_scene());
  send_goal(1, {0.8, -0.4}, {1e-4, 1e-4});
  auto plans = answers_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  ASSERT_EQ(plans[0].status, plan_t::SUCCESS) << plans[0].status_message;
  EXPECT_LE(plans[0].goal_error, 1e-4);
  send_goal(2, {0.8, -0.4}, {0, -0.1});
  plans = answers_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  EXPECT_EQ(plans[1].status, plan_t::INVALID_GOAL);
  EXPECT_NE(plans[1].status_message.find("goal_v3_t.joint_tolerance of \"joint2\" must be >= 0"),
            std::string::npos)
      << plans[1].status_message;
}

// A box mesh at the top of the swing, sent by a path relative to the daemon's scene: the replan
// avoids it (validated against the scene with the same mesh), the first plan went through it.
TEST_F(SceneMessages, AMeshObstacleByFileIsAvoided) {
  write_box_obj("block.obj", Eigen::Vector3d(0.2, 0.2, 0.2));
  start(rr_scene());
  send_goal(1, {0.8, -0.4});
  auto plans = answers_->wait_plans(1);
  ASSERT_EQ(plans.size(), 1u);
  ASSERT_EQ(plans[0].status, plan_t::SUCCESS) << plans[0].status_message;
  send_mesh("block", "block.obj", Eigen::Vector3d(0, 0, 1.85));
  plans = answers_->wait_plans(2);
  ASSERT_EQ(plans.size(), 2u);
  ASSERT_EQ(plans[1].status, plan_t::SUCCESS) << plans[1].status_message;
  const std::string with_mesh = rr_scene(
      "", "obstacles:\n  - {id: block, shape: mesh, mesh: block.obj, position: [0, 0, 1.85]}\n");
  const planning::Validation v = validate_against(with_mesh, plans[1]);
  EXPECT_TRUE(v.valid) << v.failures.front();
  EXPECT_GE(v.min_clearance, 0.0);
  EXPECT_LT(validate_against(with_mesh, plans[0]).min_clearance, 0.0);
}

TEST_F(SceneMessages, AMissingOrUnreadableMeshIsRefusedNamingTheFile) {
  start(rr_scene());
  send_mesh("gone", "no_such_mesh.obj", Eigen::Vector3d(0, 0, 1.85));
  EXPECT_TRUE(answers_->wait_status_containing(
      "mesh_obstacle_list_t.obstacles[0] (\"gone\").mesh: file 'no_such_mesh.obj' not found"));
  {
    std::ofstream(dir_ + "/junk.obj") << "this is not a mesh\n";
  }
  send_mesh("junk", dir_ + "/junk.obj", Eigen::Vector3d(0, 0, 1.85));
  EXPECT_TRUE(answers_->wait_status_containing("mesh_obstacle_list_t.obstacles[0] (\"junk\").mesh"));
  EXPECT_EQ(answers_->wait_plans(0, 0).size(), 0u);
}

}  // namespace
}  // namespace kinograph::daemon

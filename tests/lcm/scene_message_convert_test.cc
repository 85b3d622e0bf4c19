// The LCM equivalents of what scene files say: goal_v3_t's tolerances, payload_t and
// mesh_obstacle_list_t, converted exactly when good and refused naming the field when not.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "kinograph/lcm/message_convert.h"
#include "tests/lcmtypes/sample_messages.h"

namespace kinograph::messages {
namespace {

namespace fs = std::filesystem;

const dynamics::Model& rr() {
  static const dynamics::Model model =
      dynamics::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/rr/rr.urdf");
  return model;
}

RobotIdentity identity() { return {rr().name, "RR"}; }

goal_v3_t tolerant_goal(std::vector<std::string> names, std::vector<double> q,
                        std::vector<double> tolerance) {
  goal_v3_t g{};
  g.goal_id = 3;
  g.kind = goal_v3_t::KIND_JOINT_CONFIGURATION;
  g.num_joints = static_cast<int32_t>(names.size());
  g.joint_name = std::move(names);
  g.joint_position = std::move(q);
  g.joint_tolerance = std::move(tolerance);
  g.ee_quaternion[0] = 1;
  return g;
}

TEST(GoalV3FromMessage, JointTolerancesGoToTheirJointsInModelOrder) {
  GoalRequest out;
  const Check c = goal_from_message(tolerant_goal({"joint2", "joint1"}, {0.1, 0.2}, {1e-4, 0}),
                                    rr(), identity(), out);
  ASSERT_TRUE(c.ok) << c.reason;
  EXPECT_DOUBLE_EQ(out.goal.q[0], 0.2);
  EXPECT_DOUBLE_EQ(out.goal.q[1], 0.1);
  ASSERT_EQ(out.goal.joint_tolerance.size(), 2);
  EXPECT_EQ(out.goal.joint_tolerance[0], 0.0);  // the default
  EXPECT_EQ(out.goal.joint_tolerance[1], 1e-4);
  // A joint the goal does not name keeps the default tolerance.
  ASSERT_TRUE(goal_from_message(tolerant_goal({"joint1"}, {0.2}, {0.5}), rr(), identity(), out).ok);
  EXPECT_EQ(out.goal.joint_tolerance[0], 0.5);
  EXPECT_EQ(out.goal.joint_tolerance[1], 0.0);
}

TEST(GoalV3FromMessage, RefusesNegativeAndNonFiniteTolerancesNamingThem) {
  GoalRequest out;
  Check c = goal_from_message(tolerant_goal({"joint1"}, {0.2}, {-1}), rr(), identity(), out);
  EXPECT_FALSE(c.ok);
  EXPECT_EQ(c.reason, "goal_v3_t.joint_tolerance of \"joint1\" must be >= 0 (0 = the default)");
  goal_v3_t pose{};
  pose.kind = goal_v3_t::KIND_END_EFFECTOR_POSE;
  pose.ee_frame = "ee";
  pose.ee_quaternion[0] = 1;
  pose.position_tolerance_m = std::nan("");
  c = goal_from_message(pose, rr(), identity(), out);
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.reason.find("goal_v3_t.position_tolerance_m must be >= 0"), std::string::npos);
  pose.position_tolerance_m = 0.02;
  pose.orientation_tolerance_rad = 0.1;
  ASSERT_TRUE(goal_from_message(pose, rr(), identity(), out).ok);
  EXPECT_EQ(out.goal.position_tolerance, 0.02);
  EXPECT_EQ(out.goal.orientation_tolerance, 0.1);
  // goal_v2_t's checks, in goal_v3_t's name.
  c = goal_from_message(tolerant_goal({"elbow"}, {0.2}, {0}), rr(), identity(), out);
  EXPECT_EQ(c.reason, "goal_v3_t.joint_name[0] \"elbow\" is not a joint of rr");
}

TEST(PayloadFromMessage, AttachDetachAndRefusals) {
  payload_t p{};
  p.action = payload_t::ATTACH;
  p.frame = "ee";
  p.mass_kg = 1.5;
  p.size[0] = 0.1;
  p.size[1] = 0.2;
  p.size[2] = 0.3;
  p.offset[2] = 0.05;
  PayloadChange out;
  ASSERT_TRUE(payload_from_message(p, rr(), identity(), out).ok);
  ASSERT_TRUE(out.payload);
  EXPECT_EQ(out.payload->frame, "ee");
  EXPECT_EQ(out.payload->mass, 1.5);
  EXPECT_EQ(out.payload->size, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(out.payload->offset, Eigen::Vector3d(0, 0, 0.05));
  payload_t detach{};
  detach.action = payload_t::DETACH;
  ASSERT_TRUE(payload_from_message(detach, rr(), identity(), out).ok);
  EXPECT_FALSE(out.payload);

  const auto refused = [&](payload_t bad, const std::string& why) {
    PayloadChange unused;
    const Check c = payload_from_message(bad, rr(), identity(), unused);
    EXPECT_FALSE(c.ok);
    EXPECT_NE(c.reason.find(why), std::string::npos) << c.reason;
  };
  payload_t bad = p;
  bad.frame = "hand";
  refused(bad, "payload_t.frame \"hand\" is not a frame of rr");
  bad = p;
  bad.mass_kg = -1;
  refused(bad, "payload_t.mass_kg must be in [0, ");
  bad = p;
  bad.size[1] = 0;
  refused(bad, "payload_t.size must be > 0");
  bad = p;
  bad.size[0] = 1e9;
  refused(bad, "payload_t.size: box side x is");
  bad = p;
  bad.offset[0] = std::nan("");
  refused(bad, "non-finite size or offset");
  bad = p;
  bad.action = 9;
  refused(bad, "payload_t.action 9 is unknown");
  bad = p;
  bad.robot = "iiwa14";
  refused(bad, "payload_t.robot is \"iiwa14\"");
}

class MeshObstacles : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/kinograph_mesh_convert_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
    std::ofstream(dir_ + "/tetra.obj")
        << "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 2 3\nf 1 2 4\n";
    std::ofstream(dir_ + "/junk.obj") << "not a mesh\n";
  }
  void TearDown() override { fs::remove_all(dir_); }
  mesh_obstacle_list_t list(const std::string& mesh) const {
    mesh_obstacle_list_t m = lcmtypes::testing::make_mesh_obstacle_list();
    m.obstacles.resize(1);
    m.num_obstacles = 1;
    m.obstacles[0].mesh = mesh;
    m.obstacles[0].scale[0] = 2;
    return m;
  }
  std::string refusal(const mesh_obstacle_list_t& m) const {
    std::vector<ObstacleUpdate> out;
    const Check c = mesh_obstacles_from_message(m, dir_, out);
    EXPECT_FALSE(c.ok);
    EXPECT_TRUE(out.empty());
    return c.reason;
  }
  std::string dir_;
};

TEST_F(MeshObstacles, RelativeAndAbsolutePathsResolveAsInAScene) {
  std::vector<ObstacleUpdate> out;
  for (const std::string& mesh : {std::string("tetra.obj"), dir_ + "/tetra.obj"}) {
    const Check c = mesh_obstacles_from_message(list(mesh), dir_, out);
    ASSERT_TRUE(c.ok) << c.reason;
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].source, "perception");
    EXPECT_EQ(out[0].id, "part");
    EXPECT_EQ(out[0].shape.kind, collision::ShapeKind::kMesh);
    EXPECT_TRUE(fs::equivalent(out[0].shape.mesh_path, dir_ + "/tetra.obj"));
    EXPECT_EQ(out[0].shape.mesh_scale, Eigen::Vector3d(2, 1, 1));
  }
  mesh_obstacle_list_t gone = list("");
  gone.obstacles[0].action = mesh_obstacle_t::REMOVE;
  ASSERT_TRUE(mesh_obstacles_from_message(gone, dir_, out).ok);
  EXPECT_TRUE(out[0].remove);
}

TEST_F(MeshObstacles, RefusesMissingAndUnreadableFilesAndBadNumbers) {
  EXPECT_NE(refusal(list("nowhere.obj")).find("(\"part\").mesh: file 'nowhere.obj' not found"),
            std::string::npos);
  EXPECT_NE(refusal(list("junk.obj")).find("(\"part\").mesh: collision mesh"), std::string::npos);
  mesh_obstacle_list_t m = list("tetra.obj");
  m.obstacles[0].scale[1] = -1;
  EXPECT_NE(refusal(m).find("scale must be > 0"), std::string::npos);
  m = list("tetra.obj");
  m.obstacles[0].scale[1] = 1e3;
  EXPECT_NE(refusal(m).find(".scale: "), std::string::npos);
  m = list("tetra.obj");
  m.obstacles[0].position[2] = 1e9;
  EXPECT_NE(refusal(m).find("(\"part\"): "), std::string::npos);
  m = list("tetra.obj");
  m.obstacles[0].quaternion[0] = 3;
  EXPECT_NE(refusal(m).find("quaternion is not a unit quaternion"), std::string::npos);
  m = list("tetra.obj");
  m.obstacles.assign(kMaxMeshObstaclesPerMessage + 1, m.obstacles[0]);
  m.num_obstacles = static_cast<int32_t>(m.obstacles.size());
  EXPECT_NE(refusal(m).find("more than the 16 one message may carry"), std::string::npos);
}

}  // namespace
}  // namespace kinograph::messages

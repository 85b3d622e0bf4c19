// Scene files: every field parsed into the Problem, the writer's round trip, each class of error
// (with key and line), and the shipped scenes (start and goal within limits and collision-free).
#include "kinograph/planning/io/scene.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "kinograph/collision/collision_world.h"
#include "kinograph/collision/segment_checker.h"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "tests/lib/temp_dir.h"

namespace kinograph::planning {
namespace {

namespace fs = std::filesystem;

const std::string kSceneDir = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/";

// A scene with every key the schema has; the mesh and warm-start files are made by the test.
std::string full_scene(const std::string& mesh, const std::string& warm) {
  return R"(name: everything
robot:
  urdf: robots/iiwa14/iiwa14.urdf
  payload: {frame: iiwa_link_ee_kuka, mass: 2.0, size: [0.1, 0.12, 0.14], offset: [0, 0.01, 0.05]}
horizon: 2.5
steps: 25
start:
  q: [0.1, 0.2, 0.3, -0.4, 0.5, 0.6, 0.7]
  qd: [0.01, 0, 0, 0, 0, 0, -0.02]
goal:
  frame: iiwa_link_ee_kuka
  position: [0.5, 0.1, 0.6]
  rpy: [pi, 0, pi/2]
  position_only: false
limits:
  iiwa_joint_2: {lower: -1.5, upper: 1.6, velocity: 1.2, effort: 250, acceleration: 10}
  iiwa_joint_6: {effort: 35}
unactuated: [iiwa_joint_7]
obstacles:
  - {id: table, shape: box, size: [1, 0.5, 0.04], position: [0.7, 0, 0.4], rpy: [0, 0, 0.3]}
  - {id: ball, shape: sphere, size: [0.1], position: [0.3, 0.4, 0.9]}
  - {id: post, shape: cylinder, size: [0.05, 0.8], position: [-0.5, 0, 0.4],
     quaternion: [0.7071067811865476, 0.7071067811865476, 0, 0]}
  - id: bar
    shape: capsule
    size: [0.03, 0.5]
    position: [0, -0.6, 1.0]
    motion:
      - {t: 0, position: [0, -0.6, 1.0]}
      - {t: 2.5, position: [0, -0.4, 1.0], rpy: [0, 0.5, 0]}
  - {id: part, shape: mesh, mesh: )" +
         mesh + R"(, scale: [2, 2, 2], position: [0, 0.8, 0.2]}
task_constraints:
  - {frame: iiwa_link_ee_kuka, rpy: [pi, 0, 0], tolerance: 0.1}
  - {frame: iiwa_link_7, orientation_only: false, position: [0.4, 0, 0.8],
     quaternion: [1, 0, 0, 0]}
objectives:
  min_torque: 0.002
  qc: 0.5
  collision_epsilon: 0.04
  limit_epsilon: 0.01
  collision_substeps: 3
  limit_substeps: 4
planner: {formulation: dfg, init: W, warm: )" +
         warm + R"(}
camera: {eye: [3, 0, 1], target: [0, 0, 0.5]}
)";
}

// Writes a file under the test's temporary directory.
std::string write_temp(const std::string& name, const std::string& text) {
  static const kinograph::test_support::TempDir dir("kinograph_scene_test");
  const fs::path path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

class FullScene : public ::testing::Test {
 protected:
  void SetUp() override {
    mesh_ = write_temp("tetra.obj", "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 2 3\nf 1 2 4\n");
    warm_ = write_temp("warm.json", "{}\n");
  }
  std::string mesh_, warm_;
};

void expect_same_pose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  EXPECT_TRUE(a.isApprox(b, 1e-12)) << a.matrix() << "\nvs\n" << b.matrix();
}

void expect_same_scene(const Scene& a, const Scene& b) {
  const Problem &p = a.problem, &q = b.problem;
  EXPECT_EQ(p.name, q.name);
  EXPECT_EQ(a.urdf_path, b.urdf_path);
  ASSERT_EQ(a.payload.has_value(), b.payload.has_value());
  if (a.payload) {
    EXPECT_EQ(a.payload->frame, b.payload->frame);
    EXPECT_EQ(a.payload->mass, b.payload->mass);
    EXPECT_EQ(a.payload->size, b.payload->size);
    EXPECT_EQ(a.payload->offset, b.payload->offset);
  }
  ASSERT_EQ(a.limits.size(), b.limits.size());
  for (std::size_t i = 0; i < a.limits.size(); ++i) {
    EXPECT_EQ(a.limits[i].first, b.limits[i].first);
    EXPECT_EQ(a.limits[i].second.lower, b.limits[i].second.lower);
    EXPECT_EQ(a.limits[i].second.upper, b.limits[i].second.upper);
    EXPECT_EQ(a.limits[i].second.velocity, b.limits[i].second.velocity);
    EXPECT_EQ(a.limits[i].second.effort, b.limits[i].second.effort);
    EXPECT_EQ(a.limits[i].second.acceleration, b.limits[i].second.acceleration);
  }
  ASSERT_EQ(p.model->nq(), q.model->nq());
  for (int j = 0; j < p.model->nq(); ++j) {
    const dynamics::Body &x = p.model->bodies[j], &y = q.model->bodies[j];
    EXPECT_EQ(x.limits.lower, y.limits.lower);
    EXPECT_EQ(x.limits.upper, y.limits.upper);
    EXPECT_EQ(x.limits.velocity, y.limits.velocity);
    EXPECT_EQ(x.limits.effort, y.limits.effort);
    EXPECT_EQ(x.limits.acceleration, y.limits.acceleration);
    EXPECT_EQ(x.actuated, y.actuated);
    EXPECT_TRUE(x.inertia.isApprox(y.inertia, 1e-12));
  }
  EXPECT_EQ(p.horizon, q.horizon);
  EXPECT_EQ(p.steps, q.steps);
  EXPECT_EQ(p.start_q, q.start_q);
  EXPECT_EQ(p.start_qd, q.start_qd);
  EXPECT_EQ(p.goal.kind, q.goal.kind);
  EXPECT_EQ(p.goal.q, q.goal.q);
  EXPECT_EQ(p.goal.frame, q.goal.frame);
  EXPECT_EQ(p.goal.position_only, q.goal.position_only);
  expect_same_pose(p.goal.pose, q.goal.pose);
  EXPECT_EQ(a.obstacle_names, b.obstacle_names);
  ASSERT_EQ(p.obstacles.size(), q.obstacles.size());
  for (std::size_t i = 0; i < p.obstacles.size(); ++i) {
    const collision::Obstacle &x = p.obstacles[i], &y = q.obstacles[i];
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(x.shape.kind, y.shape.kind);
    EXPECT_EQ(x.shape.size, y.shape.size);
    EXPECT_EQ(x.shape.mesh_path, y.shape.mesh_path);
    EXPECT_EQ(x.shape.mesh_scale, y.shape.mesh_scale);
    expect_same_pose(x.pose, y.pose);
    ASSERT_EQ(x.trajectory.times(), y.trajectory.times());
    for (std::size_t k = 0; k < x.trajectory.times().size(); ++k) {
      expect_same_pose(x.trajectory.poses()[k], y.trajectory.poses()[k]);
    }
  }
  ASSERT_EQ(p.task_constraints.size(), q.task_constraints.size());
  for (std::size_t i = 0; i < p.task_constraints.size(); ++i) {
    EXPECT_EQ(p.task_constraints[i].frame, q.task_constraints[i].frame);
    EXPECT_EQ(p.task_constraints[i].orientation_only, q.task_constraints[i].orientation_only);
    EXPECT_EQ(p.task_constraints[i].tolerance, q.task_constraints[i].tolerance);
    expect_same_pose(p.task_constraints[i].target, q.task_constraints[i].target);
  }
  EXPECT_EQ(p.objectives.min_torque, q.objectives.min_torque);
  EXPECT_EQ(p.objectives.qc, q.objectives.qc);
  EXPECT_EQ(p.objectives.collision_epsilon, q.objectives.collision_epsilon);
  EXPECT_EQ(p.objectives.limit_epsilon, q.objectives.limit_epsilon);
  EXPECT_EQ(p.objectives.collision_substeps, q.objectives.collision_substeps);
  EXPECT_EQ(p.objectives.limit_substeps, q.objectives.limit_substeps);
  EXPECT_EQ(a.planner.formulation, b.planner.formulation);
  EXPECT_EQ(a.planner.init, b.planner.init);
  EXPECT_EQ(a.planner.warm, b.planner.warm);
}

TEST_F(FullScene, EveryFieldReachesTheProblem) {
  const Scene s = parse_scene(full_scene(mesh_, warm_));
  const Problem& p = s.problem;
  EXPECT_EQ(p.name, "everything");
  EXPECT_TRUE(fs::equivalent(s.urdf_path,
                             std::string(KINOGRAPH_SOURCE_DIR) + "/robots/iiwa14/iiwa14.urdf"));
  ASSERT_TRUE(s.payload);
  EXPECT_EQ(s.payload->size, Eigen::Vector3d(0.1, 0.12, 0.14));
  EXPECT_EQ(s.payload->offset, Eigen::Vector3d(0, 0.01, 0.05));
  const dynamics::Model bare = dynamics::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) +
                                                               "/robots/iiwa14/iiwa14.urdf");
  EXPECT_NEAR(p.model->total_mass() - bare.total_mass(), 2.0, 1e-12);
  EXPECT_NO_THROW(p.model->frame_index("payload"));
  const dynamics::JointLimits& l2 = p.model->bodies[1].limits;
  EXPECT_EQ(l2.lower, -1.5);
  EXPECT_EQ(l2.upper, 1.6);
  EXPECT_EQ(l2.velocity, 1.2);
  EXPECT_EQ(l2.effort, 250);
  EXPECT_EQ(l2.acceleration, 10);
  EXPECT_FALSE(p.model->bodies[6].actuated);  // listed under `unactuated`
  EXPECT_EQ(p.model->bodies[6].limits.effort, bare.bodies[6].limits.effort);
  EXPECT_TRUE(p.model->bodies[5].actuated);
  EXPECT_EQ(p.model->bodies[5].limits.effort, 35);
  EXPECT_EQ(s.unactuated, std::vector<std::string>{"iiwa_joint_7"});
  EXPECT_EQ(p.horizon, 2.5);
  EXPECT_EQ(p.steps, 25);
  EXPECT_DOUBLE_EQ(p.dt(), 0.1);
  EXPECT_EQ(p.start_q[3], -0.4);
  EXPECT_EQ(p.start_qd[6], -0.02);
  EXPECT_EQ(p.goal.kind, Goal::Kind::kPose);
  EXPECT_EQ(p.goal.frame, "iiwa_link_ee_kuka");
  EXPECT_EQ(p.goal.pose.translation(), Eigen::Vector3d(0.5, 0.1, 0.6));
  // rpy (π, 0, π/2): R = Rz(π/2) Rx(π) maps x → y, y → x, z → −z.
  Eigen::Matrix3d expected;
  expected << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  EXPECT_TRUE(p.goal.pose.linear().isApprox(expected, 1e-12)) << p.goal.pose.linear();
  ASSERT_EQ(p.obstacles.size(), 5u);
  EXPECT_EQ(s.obstacle_names, (std::vector<std::string>{"table", "ball", "post", "bar", "part"}));
  for (int i = 0; i < 5; ++i) EXPECT_EQ(p.obstacles[i].id, i);
  EXPECT_EQ(p.obstacles[0].shape.kind, collision::ShapeKind::kBox);
  EXPECT_EQ(p.obstacles[0].shape.size, Eigen::Vector3d(1, 0.5, 0.04));
  EXPECT_TRUE(p.obstacles[0].pose.linear().isApprox(
      Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix(), 1e-12));
  EXPECT_EQ(p.obstacles[1].shape.kind, collision::ShapeKind::kSphere);
  EXPECT_EQ(p.obstacles[1].shape.size.x(), 0.1);
  EXPECT_EQ(p.obstacles[2].shape.kind, collision::ShapeKind::kCylinder);
  EXPECT_EQ(p.obstacles[2].shape.size.head<2>(), Eigen::Vector2d(0.05, 0.8));
  EXPECT_TRUE(p.obstacles[2].pose.linear().isApprox(
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix(), 1e-12));
  EXPECT_EQ(p.obstacles[3].shape.kind, collision::ShapeKind::kCapsule);
  ASSERT_TRUE(p.obstacles[3].is_moving());
  EXPECT_EQ(p.obstacles[3].pose_at(2.5).translation(), Eigen::Vector3d(0, -0.4, 1.0));
  EXPECT_TRUE(p.obstacles[3].pose_at(1.25).translation().isApprox(Eigen::Vector3d(0, -0.5, 1.0)));
  EXPECT_EQ(p.obstacles[4].shape.kind, collision::ShapeKind::kMesh);
  EXPECT_TRUE(fs::equivalent(p.obstacles[4].shape.mesh_path, mesh_));
  EXPECT_EQ(p.obstacles[4].shape.mesh_scale, Eigen::Vector3d(2, 2, 2));
  ASSERT_EQ(p.task_constraints.size(), 2u);
  EXPECT_TRUE(p.task_constraints[0].orientation_only);
  EXPECT_EQ(p.task_constraints[0].tolerance, 0.1);
  EXPECT_FALSE(p.task_constraints[1].orientation_only);
  EXPECT_EQ(p.task_constraints[1].target.translation(), Eigen::Vector3d(0.4, 0, 0.8));
  EXPECT_EQ(p.task_constraints[1].tolerance, TaskConstraint{}.tolerance);
  EXPECT_EQ(p.objectives.min_torque, 0.002);
  EXPECT_EQ(p.objectives.qc, 0.5);
  EXPECT_EQ(p.objectives.collision_epsilon, 0.04);
  EXPECT_EQ(p.objectives.limit_epsilon, 0.01);
  EXPECT_EQ(p.objectives.collision_substeps, 3);
  EXPECT_EQ(p.objectives.limit_substeps, 4);
  EXPECT_EQ(s.planner.formulation, "dfg");
  EXPECT_EQ(s.planner.init, "W");
  EXPECT_TRUE(fs::equivalent(s.planner.warm, warm_));
}

TEST_F(FullScene, WriterRoundTripsEveryField) {
  const Scene a = parse_scene(full_scene(mesh_, warm_));
  const std::string text = scene_to_yaml(a);
  const Scene b = parse_scene(text);
  expect_same_scene(a, b);
  // Rotations pass through quaternions, so a second trip may differ in the last bit only.
  expect_same_scene(b, parse_scene(scene_to_yaml(b)));
}

TEST(Scene, JointGoalRoundTripsAndDefaults) {
  const Scene a = parse_scene(
      "robot: {urdf: robots/rr/rr.urdf}\nhorizon: 1\nsteps: 10\nstart: {q: [0, 0]}\n"
      "goal: {q: [-pi/2, 2*pi/3]}\n",
      "");
  EXPECT_EQ(a.problem.name, "scene");
  EXPECT_EQ(a.problem.goal.kind, Goal::Kind::kJoint);
  EXPECT_DOUBLE_EQ(a.problem.goal.q[0], -M_PI / 2);
  EXPECT_DOUBLE_EQ(a.problem.goal.q[1], 2 * M_PI / 3);
  EXPECT_EQ(a.problem.start_qd, Eigen::Vector2d::Zero());
  EXPECT_EQ(a.problem.objectives.qc, Objectives{}.qc);
  EXPECT_EQ(a.planner.formulation, "condensed");
  EXPECT_EQ(a.planner.init, "L");
  EXPECT_FALSE(a.payload);
  expect_same_scene(a, parse_scene(scene_to_yaml(a)));
}

// ---- errors ----

const char* kBase = R"(robot: {urdf: robots/rr/rr.urdf}
horizon: 1.0
steps: 10
start: {q: [0, 0]}
goal: {q: [1, 0]}
)";

// Parses text that must fail; returns the error for inspection.
SceneError parse_error(const std::string& text) {
  try {
    parse_scene(text, "bad.yaml");
  } catch (const SceneError& e) {
    return e;
  }
  ADD_FAILURE() << "no SceneError for:\n" << text;
  return SceneError("", "", 0, "");
}

TEST(SceneErrors, UnknownTopLevelKeyNamesKeyAndLine) {
  const SceneError e = parse_error(std::string(kBase) + "colour: red\n");
  EXPECT_EQ(e.key(), "colour");
  EXPECT_EQ(e.line(), 6);
  EXPECT_EQ(e.file(), "bad.yaml");
  EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos);
  EXPECT_NE(std::string(e.what()).find("line 6"), std::string::npos);
  EXPECT_NE(std::string(e.what()).find("unknown key"), std::string::npos);
}

TEST(SceneErrors, DuplicateKeys) {
  SceneError e = parse_error(std::string(kBase) + "horizon: 2.0\n");
  EXPECT_EQ(e.key(), "horizon");
  EXPECT_EQ(e.line(), 6);
  EXPECT_NE(std::string(e.what()).find("duplicate"), std::string::npos);
  e = parse_error(std::string(kBase) + "limits:\n  joint1: {effort: 1}\n  joint1: {effort: 2}\n");
  EXPECT_EQ(e.key(), "limits.joint1");
}

// Passive joints are listed, not given effort 0 (which would mean "no torque allowed").
TEST(SceneErrors, UnactuatedJoints) {
  SceneError e = parse_error(std::string(kBase) + "unactuated: [joint3]\n");
  EXPECT_EQ(e.key(), "unactuated[0]");
  EXPECT_EQ(e.line(), 6);
  EXPECT_NE(std::string(e.what()).find("no joint 'joint3'"), std::string::npos) << e.what();
  e = parse_error(std::string(kBase) + "unactuated: [joint1, joint1]\n");
  EXPECT_EQ(e.key(), "unactuated[1]");
  EXPECT_NE(std::string(e.what()).find("twice"), std::string::npos) << e.what();
  e = parse_error(std::string(kBase) + "unactuated: joint1\n");
  EXPECT_EQ(e.key(), "unactuated");
  e = parse_error(std::string(kBase) + "limits: {joint1: {effort: 0}}\n");
  EXPECT_EQ(e.key(), "limits.joint1.effort");
  EXPECT_NE(std::string(e.what()).find("'unactuated'"), std::string::npos) << e.what();
  const Scene ok = parse_scene(std::string(kBase) + "unactuated: [joint2]\n");
  EXPECT_TRUE(ok.problem.model->bodies[0].actuated);
  EXPECT_FALSE(ok.problem.model->bodies[1].actuated);
}

TEST(SceneErrors, UnknownNestedKey) {
  const SceneError e = parse_error(std::string(kBase) +
                                   "obstacles:\n  - {id: a, shape: sphere, size: [0.1]}\n"
                                   "  - {id: b, shape: sphere, size: [0.1], colour: red}\n");
  EXPECT_EQ(e.key(), "obstacles[1].colour");
  EXPECT_EQ(e.line(), 8);
  EXPECT_EQ(parse_error(std::string(kBase) + "objectives: {min_torq: 1}\n").key(),
            "objectives.min_torq");
  EXPECT_EQ(parse_error(std::string(kBase) + "limits: {joint1: {efort: 1}}\n").key(),
            "limits.joint1.efort");
}

TEST(SceneErrors, WrongTypes) {
  std::string text = kBase;
  text.replace(text.find("horizon: 1.0"), 12, "horizon: fast");
  SceneError e = parse_error(text);
  EXPECT_EQ(e.key(), "horizon");
  EXPECT_EQ(e.line(), 2);
  EXPECT_NE(std::string(e.what()).find("number"), std::string::npos);

  text = kBase;
  text.replace(text.find("steps: 10"), 9, "steps: 2.5");
  EXPECT_EQ(parse_error(text).key(), "steps");

  text = kBase;
  text.replace(text.find("start: {q: [0, 0]}"), 18, "start: {q: 0}");
  EXPECT_EQ(parse_error(text).key(), "start.q");

  EXPECT_EQ(parse_error(std::string(kBase) + "obstacles: {id: a}\n").key(), "obstacles");
  EXPECT_EQ(parse_error(std::string(kBase) + "planner: {init: X}\n").key(), "planner.init");
  EXPECT_EQ(parse_error(std::string(kBase) + "planner: {formulation: fast}\n").key(),
            "planner.formulation");
  EXPECT_EQ(parse_error(std::string(kBase) + "planner: {init: W}\n").key(), "planner.warm");
  EXPECT_EQ(parse_error(std::string(kBase) + "objectives: {qc: -1}\n").key(), "objectives.qc");
  EXPECT_EQ(parse_error(std::string(kBase) + "task_constraints:\n  - {frame: ee, rpy: [0, 0, x]}\n")
                .key(),
            "task_constraints[0].rpy[2]");
}

TEST(SceneErrors, WrongSizes) {
  std::string text = kBase;
  text.replace(text.find("goal: {q: [1, 0]}"), 17, "goal: {q: [1, 0, 0]}");
  const SceneError e = parse_error(text);
  EXPECT_EQ(e.key(), "goal.q");
  EXPECT_NE(std::string(e.what()).find("must have 2 numbers, has 3"), std::string::npos);
  EXPECT_EQ(
      parse_error(std::string(kBase) + "obstacles:\n  - {id: a, shape: box, size: [1, 1]}\n").key(),
      "obstacles[0].size");
  EXPECT_EQ(
      parse_error(std::string(kBase) + "obstacles:\n  - {id: a, shape: box, size: [1, -1, 1]}\n")
          .key(),
      "obstacles[0].size");
}

TEST(SceneErrors, MissingKeys) {
  std::string text = kBase;
  text.erase(text.find("steps: 10\n"), 10);
  EXPECT_EQ(parse_error(text).key(), "steps");
  EXPECT_EQ(parse_error("horizon: 1\n").key(), "robot");
  EXPECT_EQ(parse_error(std::string(kBase) + "obstacles:\n  - {shape: sphere, size: [1]}\n").key(),
            "obstacles[0].id");
  text = kBase;
  text.replace(text.find("goal: {q: [1, 0]}"), 17, "goal: {position: [1, 0, 1]}");
  EXPECT_EQ(parse_error(text).key(), "goal");
  text = kBase;
  text.replace(text.find("goal: {q: [1, 0]}"), 17, "goal: {frame: ee, position: [1, 0, 1]}");
  EXPECT_NE(std::string(parse_error(text).what()).find("rpy"), std::string::npos);
}

TEST(SceneErrors, NamesThatDoNotExist) {
  EXPECT_EQ(parse_error(std::string(kBase) + "limits: {wrist: {effort: 1}}\n").key(),
            "limits.wrist");
  std::string text = kBase;
  text.replace(text.find("goal: {q: [1, 0]}"), 17,
               "goal: {frame: hand, position: [1, 0, 1], position_only: true}");
  EXPECT_EQ(parse_error(text).key(), "goal.frame");
  text = kBase;
  text.replace(text.find("robots/rr/rr.urdf"), 17, "robots/rr/nope.urdf");
  const SceneError e = parse_error(text);
  EXPECT_EQ(e.key(), "robot.urdf");
  EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos);
  EXPECT_EQ(parse_error(std::string(kBase) + "robot: {urdf: robots/rr/rr.urdf}\n").line(), 6);
  EXPECT_EQ(
      parse_error(std::string(kBase) + "obstacles:\n  - {id: a, shape: cone, size: [1]}\n").key(),
      "obstacles[0].shape");
  EXPECT_EQ(
      parse_error(std::string(kBase) + "obstacles:\n  - {id: a, shape: mesh, mesh: no/such.obj}\n")
          .key(),
      "obstacles[0].mesh");
  text = kBase;
  text.replace(
      text.find("robot: {urdf: robots/rr/rr.urdf}"), 32,
      "robot: {urdf: robots/rr/rr.urdf, payload: {frame: hand, mass: 1, size: [1, 1, 1]}}");
  EXPECT_EQ(parse_error(text).key(), "robot.payload");
}

// Sizes that would allocate gigabytes are refused before anything is allocated, naming the key
// and the bound (steps: 2147483647 overflowed the straight-line guess's N + 1).
TEST(SceneErrors, SizesBeyondTheirBounds) {
  std::string base = kBase;
  const std::string steps = "steps: 10\n";
  for (const char* n : {"10001", "2147483647"}) {
    std::string text = base;
    text.replace(text.find(steps), steps.size(), std::string("steps: ") + n + "\n");
    const SceneError e = parse_error(text);
    EXPECT_EQ(e.key(), "steps");
    EXPECT_NE(std::string(e.what()).find("at most 10000"), std::string::npos) << e.what();
  }
  std::string ok = base;
  ok.replace(ok.find(steps), steps.size(), "steps: 10000\n");
  EXPECT_EQ(parse_scene(ok).problem.steps, 10000);
  for (const char* key : {"collision_substeps", "limit_substeps"}) {
    const SceneError e = parse_error(base + "objectives: {" + key + ": 101}\n");
    EXPECT_EQ(e.key(), std::string("objectives.") + key);
    EXPECT_NE(std::string(e.what()).find("at most 100"), std::string::npos) << e.what();
  }
}

TEST(SceneErrors, InconsistentValues) {
  EXPECT_EQ(parse_error(std::string(kBase) + "obstacles:\n  - {id: a, shape: sphere, size: [1]}\n"
                                             "  - {id: a, shape: sphere, size: [1]}\n")
                .key(),
            "obstacles[1].id");
  EXPECT_EQ(parse_error(std::string(kBase) +
                        "obstacles:\n  - {id: a, shape: sphere, size: [1], rpy: [0, 0, 0], "
                        "quaternion: [1, 0, 0, 0]}\n")
                .key(),
            "obstacles[0].quaternion");
  EXPECT_EQ(
      parse_error(std::string(kBase) +
                  "obstacles:\n  - id: a\n    shape: sphere\n    size: [1]\n    motion:\n"
                  "      - {t: 1, position: [0, 0, 0]}\n      - {t: 1, position: [1, 0, 0]}\n")
          .key(),
      "obstacles[0].motion[1].t");
  EXPECT_EQ(parse_error(std::string(kBase) + "limits: {joint1: {lower: 1, upper: 0}}\n").key(),
            "limits.joint1");
  EXPECT_EQ(parse_error(std::string(kBase) + "limits: {joint1: {effort: -1}}\n").key(),
            "limits.joint1.effort");
  EXPECT_EQ(parse_error(std::string(kBase) + "obstacles:\n  - {id: a, shape: sphere, size: [1], "
                                             "mesh: x.obj}\n")
                .key(),
            "obstacles[0].mesh");
  std::string text = kBase;
  text.replace(text.find("steps: 10"), 9, "steps: 0");
  EXPECT_EQ(parse_error(text).key(), "steps");
}

// Obstacles the collision engine cannot measure faithfully, or too many of them, are refused
// with the key, the line, the obstacle and the limit.
TEST(SceneErrors, ObstaclesBeyondTheCollisionEnginesRangeOrCount) {
  const SceneError huge = parse_error(
      std::string(kBase) + "obstacles:\n  - {id: room, shape: box, size: [1e80, 1, 1]}\n");
  EXPECT_EQ(huge.key(), "obstacles[0].size");
  EXPECT_NE(std::string(huge.what())
                .find("obstacle 'room': box side x is 1e+80 m, beyond the "
                      "10000 m"),
            std::string::npos)
      << huge.what();
  EXPECT_NE(std::string(huge.what()).find("line 7"), std::string::npos) << huge.what();
  EXPECT_EQ(parse_error(std::string(kBase) +
                        "obstacles:\n  - {id: can, shape: cylinder, size: [1e79, 1]}\n")
                .key(),
            "obstacles[0].size");
  EXPECT_EQ(parse_error(std::string(kBase) + "obstacles:\n  - {id: far, shape: sphere, size: "
                                             "[0.1], position: [0, 0, 1e6]}\n")
                .key(),
            "obstacles[0].position");
  std::string many = std::string(kBase) + "obstacles:\n";
  for (int i = 0; i <= collision::kMaxObstacles; ++i) {
    many += "  - {id: b" + std::to_string(i) + ", shape: sphere, size: [0.01], position: [3, 3, " +
            std::to_string(i) + "]}\n";
  }
  const SceneError crowd = parse_error(many);
  EXPECT_EQ(crowd.key(), "obstacles");
  EXPECT_NE(std::string(crowd.what()).find("1025 obstacles, more than the 1024"), std::string::npos)
      << crowd.what();
  // At the limits: accepted.
  const Scene ok = parse_scene(std::string(kBase) +
                               "obstacles:\n  - {id: floor, shape: box, size: [1e4, 1e4, 0.1]}\n"
                               "  - {id: can, shape: cylinder, size: [10, 10], position: [20, 0, "
                               "0]}\n");
  EXPECT_EQ(ok.problem.obstacles.size(), 2u);
}

TEST(SceneErrors, SyntaxErrorsAndMissingFiles) {
  const SceneError e = parse_error(std::string(kBase) + "obstacles: [\n  {id: a\n");
  EXPECT_GT(e.line(), 5);
  EXPECT_NE(std::string(e.what()).find("not valid YAML"), std::string::npos);
  EXPECT_EQ(parse_error("").key(), "");
  EXPECT_THROW(parse_scene("- 1\n- 2\n"), SceneError);
  try {
    load_scene("/no/such/scene.yaml");
    ADD_FAILURE() << "no error";
  } catch (const SceneError& error) {
    EXPECT_EQ(error.file(), "/no/such/scene.yaml");
  }
}

// ---- shipped scenes ----

class ShippedScene : public ::testing::TestWithParam<const char*> {};

// Smallest obstacle distance at q, or +inf without obstacles.
double clearance(const Problem& p, const Eigen::VectorXd& q, double t) {
  collision::CollisionWorld world(*p.model);
  for (const collision::Obstacle& o : p.obstacles) EXPECT_TRUE(world.add_obstacle(o).ok);
  dynamics::Data data(*p.model);
  dynamics::forward_kinematics(*p.model, data, q);
  return world.closest(data, t).distance;
}

void expect_within_limits(const dynamics::Model& model, const Eigen::VectorXd& q) {
  for (int j = 0; j < model.nq(); ++j) {
    EXPECT_GE(q[j], model.bodies[j].limits.lower) << model.bodies[j].joint_name;
    EXPECT_LE(q[j], model.bodies[j].limits.upper) << model.bodies[j].joint_name;
  }
}

TEST_P(ShippedScene, StartAndGoalAreWithinLimitsAndClear) {
  const Scene s = load_scene(kSceneDir + GetParam());
  const Problem& p = s.problem;
  EXPECT_EQ(p.name + ".yaml", GetParam());
  ASSERT_EQ(p.start_q.size(), p.model->nq());
  expect_within_limits(*p.model, p.start_q);
  EXPECT_EQ(p.start_qd, Eigen::VectorXd::Zero(p.model->nq()));
  ASSERT_EQ(p.goal.kind, Goal::Kind::kJoint);
  expect_within_limits(*p.model, p.goal.q);
  EXPECT_GE(clearance(p, p.start_q, 0), p.objectives.collision_epsilon);
  EXPECT_GE(clearance(p, p.goal.q, p.horizon), p.objectives.collision_epsilon);
  // Self-collision of the iiwa (wrist pair excluded, robots/README.md) at both ends.
  collision::CollisionWorldOptions self;
  self.self_collision = true;
  self.self_collision_excluded = {{4, 6}};
  collision::CollisionWorld world(*p.model, self);
  dynamics::Data data(*p.model);
  for (const Eigen::VectorXd& q : {p.start_q, p.goal.q}) {
    dynamics::forward_kinematics(*p.model, data, q);
    EXPECT_GT(world.closest(data).distance, 0.0);
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, ShippedScene,
                         ::testing::Values("acrobot_swingup.yaml", "rr_reach.yaml",
                                           "iiwa_desk.yaml", "iiwa_min_torque.yaml"));

TEST(ShippedScenes, AcrobotIsThePapersSwingUp) {
  const Problem p = load_scene(kSceneDir + "acrobot_swingup.yaml").problem;
  EXPECT_EQ(p.horizon, 10.0);
  EXPECT_EQ(p.steps, 100);
  EXPECT_EQ(p.start_q, Eigen::Vector2d::Zero());
  EXPECT_DOUBLE_EQ(p.goal.q[0], M_PI);
  EXPECT_EQ(p.goal.q[1], 0.0);
  EXPECT_FALSE(p.model->bodies[0].actuated);
  EXPECT_TRUE(p.model->bodies[1].actuated);
  EXPECT_EQ(p.model->bodies[1].limits.effort, 8.0);
}

// The straight joint-space line must be blocked, or the obstacle scenes test nothing.
TEST(ShippedScenes, ObstaclesBlockTheStraightLine) {
  for (const char* name : {"rr_reach.yaml", "iiwa_desk.yaml"}) {
    const Problem p = load_scene(kSceneDir + name).problem;
    collision::CollisionWorld world(*p.model);
    for (const collision::Obstacle& o : p.obstacles) ASSERT_TRUE(world.add_obstacle(o).ok);
    dynamics::Data data(*p.model);
    collision::SegmentChecker checker(*p.model);
    const collision::SegmentCheckResult r = checker.check(world, data, p.start_q, p.goal.q);
    EXPECT_LT(r.min_distance, 0.0) << name;
  }
}

TEST(ShippedScenes, MinTorqueSceneDiffersOnlyInItsWeight) {
  Scene desk = load_scene(kSceneDir + "iiwa_desk.yaml");
  Scene task2 = load_scene(kSceneDir + "iiwa_min_torque.yaml");
  EXPECT_EQ(desk.problem.objectives.min_torque, 0.0);
  EXPECT_GT(task2.problem.objectives.min_torque, 0.0);
  task2.problem.objectives.min_torque = 0.0;
  task2.problem.name = desk.problem.name;
  expect_same_scene(desk, task2);
  // The block: 2 kg more than the bare arm, centre 0.05 m beyond the flange.
  ASSERT_TRUE(desk.payload);
  EXPECT_EQ(desk.payload->mass, 2.0);
  EXPECT_EQ(desk.payload->offset, Eigen::Vector3d(0, 0, 0.05));
}

// planner.formulation names the batch planner's formulations as to_string() does; nothing else.
TEST(PlannerSpec, FormulationNamesAreTheBatchPlannersOwn) {
  EXPECT_EQ(formulation_from_name("condensed"), Formulation::kCondensed);
  EXPECT_EQ(formulation_from_name("dfg"), Formulation::kDynamicFactorGraph);
  for (Formulation f : {Formulation::kCondensed, Formulation::kDynamicFactorGraph}) {
    EXPECT_EQ(formulation_from_name(to_string(f)), f);
  }
  EXPECT_FALSE(formulation_from_name("DFG"));
  EXPECT_FALSE(formulation_from_name(""));
}

}  // namespace
}  // namespace kinograph::planning

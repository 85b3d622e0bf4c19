// Plan files as pictures: the planner's reader gives the robot, trajectory and obstacles the
// renderer draws (colours, motion), bad files fail naming the file and key, and a replan's
// changed obstacles are told apart.
#include "render/plan_scene.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tests/render/test_scenes.h"

namespace kinograph::render {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class PlanScene : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::make_test_dir("kinograph_plan_scene_test"); }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  // Expects reading the plan file at `path` to throw a message naming it and `needle`.
  void expect_error(const std::string& path, const std::string& needle) {
    try {
      planning::read_plan_file(path);
      FAIL() << "no error for " << needle;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(fs::path(path).filename().string()), std::string::npos)
          << e.what();
    }
  }
  fs::path dir_;
};

TEST_F(PlanScene, RobotTrajectoryAndObstaclesComeFromThePlanFile) {
  json j = test::iiwa_test_plan(6);
  j["robot"]["payload"] = {{"frame", "iiwa_link_ee"},
                           {"mass", 1.5},
                           {"size", {0.1, 0.1, 0.1}},
                           {"offset", {0, 0, 0.05}}};
  j["obstacles"].push_back(json::parse(R"({"id": "ball", "shape": "sphere", "size": [0.1],
      "rgba": [1, 0, 0, 1], "motion": [{"t": 0, "position": [0, 1, 1]},
                                      {"t": 2, "position": [2, 1, 1]}]})"));
  const std::string path = (dir_ / "plan.json").string();
  test::write_json(j, path);
  const planning::PlanFile file = planning::read_plan_file(path);
  const RenderScene scene = plan_scene(file);
  ASSERT_EQ(scene.model, file.model.get());
  const dynamics::Model bare = dynamics::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) +
                                                               "/robots/iiwa14/iiwa14.urdf");
  EXPECT_EQ(scene.model->visual.size(), bare.visual.size() + 1);  // the payload box shows
  // The plan's interpolant, kDrawnSamplesPerInterval points per interval: each interval's
  // first point is its knot, and the last point is at the last knot's time.
  const std::size_t per = kDrawnSamplesPerInterval;
  ASSERT_EQ(scene.trajectory.t.size(), 6 * per + 1);
  ASSERT_EQ(scene.trajectory.q.size(), 6 * per + 1);
  for (std::size_t k = 0; k < 6; ++k) {
    EXPECT_EQ(scene.trajectory.t[k * per], j["t"][k].get<double>());
    for (int i = 0; i < 7; ++i) {
      EXPECT_EQ(scene.trajectory.q[k * per][i], j["q"][k][i].get<double>());
    }
  }
  EXPECT_EQ(scene.trajectory.t.back(), j["t"][6].get<double>());
  ASSERT_EQ(scene.obstacles.size(), 2u);
  const SceneObstacle &desk = scene.obstacles[0], &ball = scene.obstacles[1];
  EXPECT_EQ(desk.name, "desk");
  EXPECT_EQ(desk.rgba, SceneObstacle().rgba);  // no colour in the file: the default blue
  EXPECT_EQ(desk.obstacle.shape.kind, collision::ShapeKind::kBox);
  EXPECT_TRUE(desk.obstacle.pose.translation().isApprox(Eigen::Vector3d(0.7, 0.5, 0.2)));
  EXPECT_EQ(ball.rgba, Eigen::Vector4d(1, 0, 0, 1));
  ASSERT_TRUE(ball.obstacle.is_moving());
  EXPECT_TRUE(ball.obstacle.pose_at(1.0).translation().isApprox(Eigen::Vector3d(1, 1, 1)));
}

TEST_F(PlanScene, TrajectoryInterpolatesAndClamps) {
  Trajectory tr;
  tr.t = {0.0, 1.0, 3.0};
  tr.q = {Eigen::VectorXd::Constant(1, 0.0), Eigen::VectorXd::Constant(1, 2.0),
          Eigen::VectorXd::Constant(1, 6.0)};
  EXPECT_DOUBLE_EQ(tr.at(0.5)[0], 1.0);
  EXPECT_DOUBLE_EQ(tr.at(2.0)[0], 4.0);
  EXPECT_DOUBLE_EQ(tr.at(-1.0)[0], 0.0);
  EXPECT_DOUBLE_EQ(tr.at(9.0)[0], 6.0);
  EXPECT_EQ(tr.even_times(4), (std::vector<double>{0.0, 1.0, 2.0, 3.0}));
  EXPECT_EQ(tr.even_times(1), (std::vector<double>{0.0}));
}

TEST_F(PlanScene, BadInputNamesFileAndKey) {
  // robots/rr/rr.urdf has two joints; rows without joint_names are taken in its order.
  const std::string rows = R"("qd": [[0, 0], [0, 0]], "qdd": [[0, 0], [0, 0]],
                              "tau": [[0, 0], [0, 0]])";
  const auto plan = [&](const std::string& name, const std::string& body) {
    return write(name, "{\"robot\": {\"urdf\": \"robots/rr/rr.urdf\"}, " + body + "}");
  };
  expect_error((dir_ / "missing.json").string(), "missing.json");
  expect_error(write("broken.json", "{\"robot\": "), "not valid JSON");
  expect_error(write("norobot.json", R"({"t": [0], "q": [[0, 0]]})"), "'robot'");
  expect_error(write("badurdf.json", R"({"robot": {"urdf": "robots/gone.urdf"}})"),
               "robots/gone.urdf");
  expect_error(plan("noq.json", R"("t": [0, 1], )" + rows), "'q'");
  expect_error(plan("rows.json", R"("t": [0, 1], "q": [[0, 0]], )" + rows), "'q': has 1 rows");
  expect_error(plan("ragged.json", R"("t": [0, 1], "q": [[0, 1], [0]], )" + rows), "'q[1]'");
  expect_error(plan("time.json", R"("t": [1, 0], "q": [[0, 0], [0, 0]], )" + rows), "'t[1]'");
  expect_error(plan("num.json", R"("t": [0, "a"], "q": [[0, 0], [0, 0]], )" + rows), "'t[1]'");
  expect_error(plan("shape.json", R"("obstacles": [{"shape": "torus", "size": [1]}])"), "torus");
  expect_error(plan("size.json", R"("obstacles": [{"shape": "box", "size": [1, 2]}])"),
               "obstacles[0].size");
  expect_error(plan("mesh.json", R"("obstacles": [{"shape": "mesh", "mesh": "meshes/gone.stl"}])"),
               "meshes/gone.stl");
  expect_error(plan("rgba.json", R"("obstacles": [{"size": [1, 1, 1], "rgba": [1, 0, 0]}])"),
               "obstacles[0].rgba");
}

TEST(ChangedObstacles, NewMovedAndReshapedAreMarkedAndOnlyThey) {
  const auto obstacle = [](const std::string& name, const collision::Shape& shape,
                           const Eigen::Vector3d& at) {
    SceneObstacle o;
    o.name = name;
    o.obstacle.shape = shape;
    o.obstacle.pose.translation() = at;
    return o;
  };
  RenderScene before, after;
  before.obstacles = {obstacle("desk", collision::Shape::box(1, 1, 0.1), {1, 0, 0.5}),
                      obstacle("post", collision::Shape::cylinder(0.1, 1), {0, 1, 0.5}),
                      obstacle("ball", collision::Shape::sphere(0.2), {0, -1, 1})};
  after.obstacles = {obstacle("desk", collision::Shape::box(1, 1, 0.1), {1, 0, 0.5}),
                     obstacle("post", collision::Shape::cylinder(0.1, 1), {0, 1.2, 0.5}),
                     obstacle("ball", collision::Shape::sphere(0.3), {0, -1, 1}),
                     obstacle("box", collision::Shape::box(0.1, 0.1, 0.1), {1, 0, 0.6})};
  // A ball that starts where it was but then moves has changed too.
  RenderScene moving = before;
  moving.obstacles[2].obstacle.trajectory = collision::PoseTrajectory(
      {0.0, 1.0},
      {moving.obstacles[2].obstacle.pose, Eigen::Isometry3d(Eigen::Translation3d(0, 0, 1))});
  const Eigen::Vector4d marked(1, 0, 1, 1);
  EXPECT_EQ(highlight_changed_obstacles(before, after, marked), 3);
  EXPECT_NE(after.obstacles[0].rgba, marked);
  for (int i = 1; i < 4; ++i) EXPECT_EQ(after.obstacles[i].rgba, marked) << i;
  RenderScene unchanged = before;
  EXPECT_EQ(highlight_changed_obstacles(before, unchanged, marked), 0);
  EXPECT_EQ(highlight_changed_obstacles(before, moving, marked), 1);
  EXPECT_EQ(moving.obstacles[2].rgba, marked);
}

}  // namespace
}  // namespace kinograph::render

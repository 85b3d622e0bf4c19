// Plan file reader: round trip, model/obstacle/trajectory conversion, and bad input.
#include "render/plan_json.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tests/render/test_scenes.h"

namespace kinograph::render {
namespace {

namespace fs = std::filesystem;

class PlanJson : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           (std::string("kinograph_plan_json_test") + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  // Expects read_plan_json(path) to throw a message containing `needle`.
  void expect_error(const std::string& path, const std::string& needle) {
    try {
      read_plan_json(path);
      FAIL() << "no error for " << needle;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  }
  fs::path dir_;
};

TEST_F(PlanJson, RoundTripKeepsEveryField) {
  PlanFile plan = test::iiwa_test_plan(6);
  plan.payload = PlanPayload{"iiwa_link_ee", 2.0, {0.1, 0.1, 0.2}, {0, 0, 0.1}};
  PlanObstacle ball;
  ball.id = "ball";
  ball.shape = "sphere";
  ball.size = {0.1};
  ball.quaternion = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  ball.rgba = Eigen::Vector4d(1, 0, 0, 1);
  plan.obstacles.push_back(ball);
  plan.qd = plan.q;
  plan.stats = {{"iterations", 12}};
  plan.name = "iiwa desk";
  const std::string path = (dir_ / "plan.json").string();
  write_plan_json(plan, path);
  const PlanFile back = read_plan_json(path);
  EXPECT_EQ(back.urdf, plan.urdf);
  EXPECT_EQ(back.name, "iiwa desk");
  ASSERT_TRUE(back.payload.has_value());
  EXPECT_EQ(back.payload->frame, "iiwa_link_ee");
  EXPECT_DOUBLE_EQ(back.payload->mass, 2.0);
  EXPECT_EQ(back.joint_names, plan.joint_names);
  EXPECT_EQ(back.t, plan.t);
  ASSERT_EQ(back.q.size(), plan.q.size());
  EXPECT_TRUE(back.q[3].isApprox(plan.q[3]));
  EXPECT_TRUE(back.tau[5].isApprox(plan.tau[5]));
  EXPECT_EQ(back.qd.size(), plan.q.size());
  EXPECT_TRUE(back.qdd.empty());
  EXPECT_EQ(back.effort_limits, plan.effort_limits);
  ASSERT_EQ(back.obstacles.size(), 2u);
  EXPECT_TRUE(back.obstacles[1].quaternion.isApprox(ball.quaternion));
  EXPECT_EQ(back.stats["iterations"], 12);
}

TEST_F(PlanJson, ModelObstaclesAndTrajectoryFromThePlan) {
  PlanFile plan = test::iiwa_test_plan(4);
  // Columns in reverse order: the trajectory must come back in the model's joint order.
  std::reverse(plan.joint_names.begin(), plan.joint_names.end());
  for (Eigen::VectorXd& q : plan.q) q.reverseInPlace();
  plan.payload = PlanPayload{"iiwa_link_ee", 1.5, {0.1, 0.1, 0.1}, {0, 0, 0.05}};
  plan.source = (dir_ / "plan.json").string();
  const dynamics::Model model = load_plan_model(plan);
  const dynamics::Model bare = dynamics::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) +
                                                               "/robots/iiwa14/iiwa14.urdf");
  EXPECT_EQ(model.nq(), 7);
  EXPECT_EQ(model.visual.size(), bare.visual.size() + 1);  // the payload box shows
  const Trajectory tr = plan_trajectory(plan, model);
  ASSERT_EQ(tr.q.size(), plan.q.size());
  EXPECT_DOUBLE_EQ(tr.q[2][0], plan.q[2][6]);
  EXPECT_DOUBLE_EQ(tr.q[2][6], plan.q[2][0]);
  const auto obstacles = plan_obstacles(plan);
  ASSERT_EQ(obstacles.size(), 1u);
  EXPECT_EQ(obstacles[0].body, -1);
  EXPECT_EQ(obstacles[0].shape, dynamics::Geometry::Shape::kBox);
  EXPECT_TRUE(obstacles[0].origin.translation().isApprox(Eigen::Vector3d(0.7, 0.5, 0.2)));
  plan.joint_names[0] = "not_a_joint";
  EXPECT_THROW(plan_trajectory(plan, model), std::runtime_error);
}

TEST_F(PlanJson, TrajectoryInterpolatesAndClamps) {
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

TEST_F(PlanJson, BadInputNamesFileAndKey) {
  expect_error((dir_ / "missing.json").string(), "missing.json");
  expect_error(write("broken.json", "{\"robot\": "), "not valid JSON");
  expect_error(write("norobot.json", R"({"t": [0], "q": [[0]]})"), "robot");
  expect_error(write("noq.json", R"({"robot": {"urdf": "x.urdf"}, "t": [0, 1]})"), "'q'");
  expect_error(write("rows.json", R"({"robot": {"urdf": "x.urdf"}, "t": [0, 1], "q": [[0]]})"),
               "'q' has 1 rows");
  expect_error(
      write("ragged.json", R"({"robot": {"urdf": "x.urdf"}, "t": [0, 1], "q": [[0, 1], [0]]})"),
      "q[1]");
  expect_error(write("time.json", R"({"robot": {"urdf": "x.urdf"}, "t": [1, 0], "q": [[0], [0]]})"),
               "t[1]");
  expect_error(write("shape.json", R"({"robot": {"urdf": "x.urdf"}, "t": [0], "q": [[0]],
                                       "obstacles": [{"shape": "torus", "size": [1]}]})"),
               "torus");
  expect_error(write("size.json", R"({"robot": {"urdf": "x.urdf"}, "t": [0], "q": [[0]],
                                      "obstacles": [{"shape": "box", "size": [1, 2]}]})"),
               "obstacles[0].size");
  expect_error(write("num.json", R"({"robot": {"urdf": "x.urdf"}, "t": [0, "a"], "q": [[0]]})"),
               "t[1]");
}

TEST_F(PlanJson, MissingUrdfAndObstacleMeshAreClearErrors) {
  PlanFile plan = test::iiwa_test_plan(2);
  plan.source = (dir_ / "plan.json").string();
  plan.urdf = "robots/no_such_robot.urdf";
  try {
    load_plan_model(plan);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_robot.urdf"), std::string::npos);
  }
  PlanObstacle mesh;
  mesh.shape = "mesh";
  mesh.mesh = "meshes/gone.stl";
  plan.obstacles.push_back(mesh);
  try {
    plan_obstacles(plan);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("meshes/gone.stl"), std::string::npos);
  }
}

TEST_F(PlanJson, RelativePathsResolveNextToThePlan) {
  write("part.stl", "solid x\nendsolid x\n");
  const std::string plan_path = (dir_ / "plan.json").string();
  EXPECT_EQ(resolve_plan_path("part.stl", plan_path), fs::canonical(dir_ / "part.stl").string());
  EXPECT_EQ(resolve_plan_path("robots/rr/rr.urdf", plan_path),
            fs::canonical(fs::path(KINOGRAPH_SOURCE_DIR) / "robots/rr/rr.urdf").string());
  EXPECT_EQ(resolve_plan_path("/abs/path.urdf", plan_path), "/abs/path.urdf");
}

}  // namespace
}  // namespace kinograph::render

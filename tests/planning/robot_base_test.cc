// robot.base in scene and plan files: the robot's model is placed there, the pose survives the
// scene writer and the plan file, and a bad base names its key.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/io/plan_json.h"
#include "kinograph/planning/io/scene.h"

namespace kinograph::planning {
namespace {

const std::string kSource = KINOGRAPH_SOURCE_DIR;

std::string scene_text(const std::string& base) {
  return "robot:\n  urdf: " + kSource + "/robots/iiwa14/iiwa14.urdf\n" + base +
         "horizon: 2\nsteps: 10\nstart: {q: [0, 0, 0, 0, 0, 0, 0]}\n"
         "goal: {q: [0.1, 0, 0, 0, 0, 0, 0]}\n";
}

Eigen::Isometry3d flange_at_zero(const dynamics::Model& model) {
  dynamics::Data data(model);
  dynamics::forward_kinematics(model, data, Eigen::VectorXd::Zero(model.nq()));
  return dynamics::frame_pose(model, data, model.frame_index("iiwa_link_ee_kuka"));
}

TEST(RobotBase, PlacesTheModelAndSurvivesTheWriterAndThePlanFile) {
  const Scene origin = parse_scene(scene_text(""));
  const Scene placed =
      parse_scene(scene_text("  base: {position: [1.3, 0.2, 0], rpy: [0, 0, pi]}\n"));
  Eigen::Isometry3d base = Eigen::Isometry3d::Identity();
  base.translation() = Eigen::Vector3d(1.3, 0.2, 0);
  base.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_TRUE(placed.base.isApprox(base, 1e-12));
  const Eigen::Isometry3d expected = base * flange_at_zero(*origin.problem.model);
  EXPECT_TRUE(flange_at_zero(*placed.problem.model).isApprox(expected, 1e-12));
  // A robot on the floor stays on it: the floor follows the placed base geometry.
  EXPECT_EQ(placed.problem.self_and_floor.floor.has_value(),
            origin.problem.self_and_floor.floor.has_value());

  const Scene again = parse_scene(scene_to_yaml(placed));
  EXPECT_TRUE(again.base.isApprox(base, 1e-12));
  EXPECT_TRUE(flange_at_zero(*again.problem.model).isApprox(expected, 1e-12));

  Plan plan;
  for (int k = 0; k <= placed.problem.steps; ++k) plan.t.push_back(k * placed.problem.dt());
  const int rows = placed.problem.steps + 1;
  plan.q = plan.qd = plan.qdd = plan.tau = Eigen::MatrixXd::Zero(rows, 7);
  const nlohmann::json j = plan_to_json(plan, placed);
  EXPECT_EQ(j["format_version"], kPlanFormatVersion);
  const PlanFileInfo info = plan_info_from_json(j, "placed.json");
  EXPECT_TRUE(info.base.isApprox(base, 1e-12));
  EXPECT_TRUE(flange_at_zero(load_plan_model(info)).isApprox(expected, 1e-12));

  // A robot at the origin writes no base, and reads back at the origin.
  const nlohmann::json at_origin = plan_to_json(plan, origin);
  EXPECT_FALSE(at_origin["robot"].contains("base"));
  EXPECT_TRUE(plan_info_from_json(at_origin, "origin.json").base.isApprox(
      Eigen::Isometry3d::Identity(), 0));
}

TEST(RobotBase, BadBasesNameTheirKey) {
  const auto error = [](const std::string& base) {
    try {
      parse_scene(scene_text(base), "s.yaml");
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("  base: {position: [1, 2]}\n").find("robot.base.position"), std::string::npos);
  EXPECT_NE(error("  base: {position: [0, 0, 0], rpy: [0, 0, 0], quaternion: [1, 0, 0, 0]}\n")
                .find("robot.base.quaternion"),
            std::string::npos);
  EXPECT_NE(error("  base: {position: [0, 0, 0], tilt: 3}\n").find("robot.base"),
            std::string::npos);
  EXPECT_NE(error("  base: {position: [.nan, 0, 0]}\n").find("robot.base.position"),
            std::string::npos);
  EXPECT_NE(error("  base: {quaternion: [0, 0, 0, 0]}\n").find("must not be zero"),
            std::string::npos);

  nlohmann::json j = plan_to_json(Plan{}, parse_scene(scene_text("")));
  j["robot"]["base"] = "left";
  try {
    plan_info_from_json(j, "p.json");
    ADD_FAILURE() << "a base that is not an object was read";
  } catch (const PlanFileError& e) {
    EXPECT_NE(std::string(e.what()).find("robot.base"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace kinograph::planning

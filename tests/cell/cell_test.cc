// Cell files: the shipped two-arm cell gives one scene per robot (its base, the shared table);
// bad input names the file, the key path in the cell and the line.
#include "kinograph/cell/cell.h"

#include <gtest/gtest.h>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"

namespace kinograph::cell {
namespace {

const std::string kCells = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/cells/";

// A valid two-robot cell; tests replace one line of it.
std::string cell_text() {
  return "name: pair\n"                                                   // 1
         "horizon: 2.0\n"                                                 // 2
         "steps: 20\n"                                                    // 3
         "obstacles:\n"                                                   // 4
         "  - {id: table, shape: box, size: [0.5, 0.9, 0.45], position: [0, 0, 0.225]}\n"  // 5
         "robots:\n"                                                      // 6
         "  - name: a\n"                                                  // 7
         "    robot: {urdf: robots/iiwa14/iiwa14.urdf, base: {position: [-0.65, 0, 0]}}\n"  // 8
         "    start: {q: [0.5, 0.3, 0, -1.5, 0, 0.9, 0]}\n"               // 9
         "    goal: {q: [-0.35, 0.7, 0, -1.2, 0, 0.9, 0]}\n"              // 10
         "  - name: b\n"                                                  // 11
         "    robot: {urdf: robots/iiwa14/iiwa14.urdf, base: {position: [0.65, 0, 0], rpy: [0, 0, pi]}}\n"
         "    start: {q: [0.5, 0.3, 0, -1.5, 0, 0.9, 0]}\n"               // 13
         "    goal: {q: [-0.35, 0.7, 0, -1.2, 0, 0.9, 0]}\n";             // 14
}

std::string replace_line(const std::string& text, int line, const std::string& with) {
  std::string out;
  std::size_t start = 0;
  for (int l = 1; start < text.size(); ++l) {
    const std::size_t end = text.find('\n', start);
    out += (l == line ? with : text.substr(start, end - start)) + "\n";
    start = end + 1;
  }
  return out;
}

// The error of parsing `text`: key path and line.
planning::SceneError error_of(const std::string& text) {
  try {
    parse_cell(text, "bad_cell.yaml");
  } catch (const planning::SceneError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return planning::SceneError("", "", 0, "");
}

TEST(CellTest, ShippedTwoArmCellGivesOneSceneEachAtItsBase) {
  const Cell cell = load_cell(kCells + "two_iiwa_table.yaml");
  EXPECT_EQ(cell.name, "two_iiwa_table");
  ASSERT_EQ(cell.robots.size(), 2u);
  EXPECT_EQ(cell.robot_index("arm1"), 1);
  EXPECT_THROW(cell.robot_index("nobody"), std::out_of_range);
  for (const CellRobot& robot : cell.robots) {
    const planning::Scene& s = robot.scene;
    EXPECT_EQ(s.problem.name, "two_iiwa_table." + robot.name);
    ASSERT_EQ(s.obstacle_names.size(), 1u);
    EXPECT_EQ(s.obstacle_names[0], "table");
    EXPECT_EQ(s.problem.steps, 30);
    EXPECT_DOUBLE_EQ(s.problem.objectives.limit_epsilon, 0.03);
    EXPECT_FALSE(s.problem.self_and_floor.allowed_pairs.empty());  // the SRDF's wrist pair
    // The root link stands at the base pose: link 0's frame is the base.
    const dynamics::Model& m = *s.problem.model;
    dynamics::Data d(m);
    dynamics::forward_kinematics(m, d, s.problem.start_q);
    const Eigen::Isometry3d root = dynamics::frame_pose(m, d, m.frame_index("iiwa_link_0"));
    EXPECT_TRUE(root.isApprox(s.base, 1e-12));
  }
  EXPECT_NEAR(cell.robots[0].scene.base.translation().x(), -0.65, 1e-12);
  EXPECT_NEAR(cell.robots[1].scene.base.translation().x(), 0.65, 1e-12);
  EXPECT_TRUE(cell.robots[1].scene.base.linear().isApprox(
      Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix(), 1e-6));  // as written
}

TEST(CellTest, TextParsesAndRelativePathsFindTheDataDirectory) {
  const Cell cell = parse_cell(cell_text(), "pair.yaml");
  ASSERT_EQ(cell.robots.size(), 2u);
  EXPECT_EQ(cell.robots[1].name, "b");
  EXPECT_DOUBLE_EQ(cell.robots[1].scene.problem.horizon, 2.0);
}

TEST(CellTest, ErrorsNameTheCellsKeyPathAndLine) {
  struct Case {
    int line;
    std::string text, key;
    int error_line;
    std::string message;
  };
  const std::vector<Case> cases = {
      {10, "    goal: {q: [-0.35, 0.7, 0, -1.2, 0, 0.9]}", "robots[0].goal.q", 10, "7 numbers"},
      {13, "    start: {q: [0.5, 0.3, 0, -1.5, 0, 0.9, x]}", "robots[1].start.q[6]", 13,
       "must be a number"},
      {5, "  - {id: table, shape: box, size: [0.5, -0.9, 0.45], position: [0, 0, 0.225]}",
       "obstacles[0].size", 5, ""},
      {11, "  - name: a", "robots[1].name", 11, "two robots are named 'a'"},
      {7, "  - name: a/b", "robots[0].name", 7, "must not contain '/'"},
      {9, "    begin: {q: [0.5, 0.3, 0, -1.5, 0, 0.9, 0]}", "robots[0].begin", 9, "unknown key"},
      {8, "    robot: {urdf: robots/iiwa14/no_such.urdf}", "robots[0].robot.urdf", 8, "not found"},
      {8, "    robot: {urdf: robots/iiwa14/iiwa14.urdf, base: {position: [0, 0, 0], rpy: [0, 0]}}",
       "robots[0].robot.base.rpy", 8, "3 numbers"},
      {2, "horizons: 2.0", "horizons", 2, "unknown key"},
  };
  for (const Case& c : cases) {
    const planning::SceneError e = error_of(replace_line(cell_text(), c.line, c.text));
    EXPECT_EQ(e.key(), c.key) << e.what();
    EXPECT_EQ(e.line(), c.error_line) << e.what();
    EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bad_cell.yaml"), std::string::npos) << e.what();
  }
}

TEST(CellTest, MissingPartsAreNamed) {
  EXPECT_EQ(error_of(replace_line(cell_text(), 10, "")).key(), "robots[0].goal");
  EXPECT_EQ(error_of(replace_line(cell_text(), 3, "")).key(), "steps");
  EXPECT_EQ(error_of("name: x\nhorizon: 1\nsteps: 2\nrobots: []\n").key(), "robots");
  EXPECT_EQ(error_of("").line(), 0);
  EXPECT_NE(std::string(error_of("robots: [").what()).find("not valid YAML"), std::string::npos);
  EXPECT_THROW(load_cell(kCells + "no_such_cell.yaml"), planning::SceneError);
}

}  // namespace
}  // namespace kinograph::cell

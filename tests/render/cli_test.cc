// The `kinograph render` and `kinograph plot` verbs end to end: pictures of the asked size,
// clear errors and non-zero exits for bad input.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include "render/image.h"
#include "render/plan_json.h"
#include "tests/render/test_scenes.h"

namespace kinograph::render {
namespace {

namespace fs = std::filesystem;

struct CliRun {
  int status = -1;
  std::string output;
};

CliRun run(const std::string& args) {
  const std::string command = std::string(KINOGRAPH_CLI) + " " + args + " 2>&1";
  CliRun result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 512> buffer;
  while (fgets(buffer.data(), buffer.size(), pipe) != nullptr) result.output += buffer.data();
  result.status = pclose(pipe);
  return result;
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           (std::string("kinograph_render_cli_test") + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    plan_ = (dir_ / "iiwa.json").string();
    write_plan_json(test::iiwa_test_plan(10), plan_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  std::string plan_;
};

TEST_F(Cli, RenderStripAndGhostWritePicturesOfTheAskedSize) {
  const std::string out = (dir_ / "strip.png").string();
  CliRun r = run("render " + plan_ + " --frames 3 --width 600 --height 200 --out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  Image image = read_png(out);
  EXPECT_EQ(image.width, 600);
  EXPECT_EQ(image.height, 200);
  const std::string ghost = (dir_ / "ghost.png").string();
  r = run("render " + plan_ + " --style ghost --width 300 --height 240 --out " + ghost);
  ASSERT_EQ(r.status, 0) << r.output;
  image = read_png(ghost);
  EXPECT_EQ(image.width, 300);
  EXPECT_EQ(image.height, 240);
}

TEST_F(Cli, PlotOverlaysTwoPlans) {
  const std::string out = (dir_ / "torque.png").string();
  const CliRun r = run("plot " + plan_ + " " + plan_ + " --width 800 --out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(read_png(out).width, 800);
}

TEST_F(Cli, BadInputFailsWithAMessage) {
  CliRun r = run("render " + (dir_ / "nope.json").string() + " --out " + (dir_ / "x.png").string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("nope.json"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "x.png"));

  r = run("render " + plan_ + " --frames 0 --out " + (dir_ / "x.png").string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("frames"), std::string::npos) << r.output;

  // A URDF whose mesh is missing: the error names the mesh.
  std::ofstream(dir_ / "robot.urdf") << R"(<robot name="m"><link name="a"/>
    <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
      <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
    <link name="b"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
      <visual><geometry><mesh filename="meshes/missing_part.stl"/></geometry></visual></link></robot>)";
  PlanFile plan;
  plan.urdf = (dir_ / "robot.urdf").string();
  plan.t = {0.0, 1.0};
  plan.q = {Eigen::VectorXd::Zero(1), Eigen::VectorXd::Ones(1)};
  write_plan_json(plan, (dir_ / "mesh.json").string());
  r = run("render " + (dir_ / "mesh.json").string() + " --out " + (dir_ / "x.png").string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("missing_part.stl"), std::string::npos) << r.output;

  r = run("plot " + (dir_ / "mesh.json").string() + " --out " + (dir_ / "x.png").string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("tau"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace kinograph::render

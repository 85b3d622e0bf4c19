// The `kinograph render` and `kinograph plot` verbs end to end: pictures of the asked size,
// clear errors and non-zero exits for bad input.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include "render/image.h"
#include "tests/render/test_scenes.h"

namespace kinograph::render {
namespace {

namespace fs = std::filesystem;

struct CliRun {
  int status = -1;
  std::string output;
};

CliRun run(const std::string& args) {
  // Under AddressSanitizer, third-party leaks at exit (fontconfig, OSMesa) are suppressed.
  const std::string command = "LSAN_OPTIONS=suppressions=" + std::string(KINOGRAPH_SOURCE_DIR) +
                              "/tests/render/lsan.supp " + std::string(KINOGRAPH_CLI) + " " + args +
                              " 2>&1";
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
    dir_ = test::make_test_dir("kinograph_render_cli_test");
    plan_ = (dir_ / "iiwa.json").string();
    test::write_json(test::iiwa_test_plan(10), plan_);
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

TEST_F(Cli, CompareDrawsTwoPlansInOneView) {
  // The second plan: another goal, and a box added beside the path.
  nlohmann::json after = test::iiwa_test_plan(10);
  for (auto& row : after["q"]) row[0] = row[0].get<double>() * 0.5;
  after["obstacles"].push_back(
      {{"id", "box"}, {"shape", "box"}, {"size", {0.2, 0.2, 0.2}}, {"position", {0.3, -0.6, 0.1}}});
  const std::string after_path = (dir_ / "after.json").string();
  test::write_json(after, after_path);
  const std::string out = (dir_ / "compare.png").string();
  const CliRun r = run("render " + plan_ + " --compare " + after_path +
                       " --frames 4 --width 640 --height 480 --out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  const Image image = read_png(out);
  EXPECT_EQ(image.width, 640);
  EXPECT_EQ(image.height, 480);
  // The changed obstacle's highlight (magenta) shows somewhere.
  int magenta = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.at(x, y);
      magenta += p[0] > p[1] + 60 && p[2] > p[1] + 40;
    }
  }
  EXPECT_GT(magenta, 100);
}

TEST_F(Cli, PlotOverlaysTwoPlans) {
  const std::string out = (dir_ / "torque.png").string();
  const CliRun r = run("plot " + plan_ + " " + plan_ + " --width 800 --out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(read_png(out).width, 800);
}

TEST_F(Cli, FailedPlanIsDrawnMarkedFailed) {
  // Red edge pixels along the picture's left and bottom edges.
  const auto red_edge = [](const Image& image) {
    int red = 0;
    for (int y = 0; y < image.height; ++y) {
      const std::uint8_t* p = image.at(0, y);
      red += p[0] > 180 && p[1] < 60 && p[2] < 60;
    }
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.at(x, image.height - 1);
      red += p[0] > 180 && p[1] < 60 && p[2] < 60;
    }
    return red;
  };
  const std::string valid_out = (dir_ / "valid.png").string();
  CliRun r = run("render " + plan_ + " --frames 3 --width 600 --height 200 --out " + valid_out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(red_edge(read_png(valid_out)), 0);

  nlohmann::json failed = test::iiwa_test_plan(10);
  failed["validation"] = {{"valid", false}, {"failures", {"goal error 0.2 exceeds 0.01"}}};
  const std::string failed_plan = (dir_ / "failed.json").string();
  test::write_json(failed, failed_plan);
  const std::string failed_out = (dir_ / "failed.png").string();
  r = run("render " + failed_plan + " --frames 3 --width 600 --height 200 --out " + failed_out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(red_edge(read_png(failed_out)), 600 + 200);
  // Compared with a valid plan, a failed one marks the picture too.
  const std::string compare_out = (dir_ / "compare_failed.png").string();
  r = run("render " + plan_ + " --compare " + failed_plan +
          " --frames 3 --width 400 --height 300 --out " + compare_out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(red_edge(read_png(compare_out)), 400 + 300);
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
  nlohmann::json plan = {{"robot", {{"urdf", (dir_ / "robot.urdf").string()}}},
                         {"t", {0.0, 1.0}},
                         {"q", {{0.0}, {1.0}}},
                         {"qd", {{0.0}, {0.0}}},
                         {"qdd", {{0.0}, {0.0}}},
                         {"tau", {{0.0}, {0.0}}}};
  test::write_json(plan, (dir_ / "mesh.json").string());
  r = run("render " + (dir_ / "mesh.json").string() + " --out " + (dir_ / "x.png").string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("missing_part.stl"), std::string::npos) << r.output;

  // A two-joint arm's plan without torques.
  plan["robot"]["urdf"] = "robots/rr/rr.urdf";
  for (const char* key : {"q", "qd", "qdd"}) plan[key] = {{0.0, 0.0}, {0.5, 0.5}};
  plan.erase("tau");
  test::write_json(plan, (dir_ / "notau.json").string());
  r = run("plot " + (dir_ / "notau.json").string() + " --out " + (dir_ / "x.png").string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("notau.json"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("'tau'"), std::string::npos) << r.output;

  // A comparison of plans of different robots.
  plan["tau"] = plan["q"];
  test::write_json(plan, (dir_ / "rr.json").string());
  r = run("render " + plan_ + " --compare " + (dir_ / "rr.json").string() + " --out " +
          (dir_ / "x.png").string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("joints"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace kinograph::render

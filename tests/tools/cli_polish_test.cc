// The CLI's contract with its user, run as the real binary: --version, one exit-code table,
// global options after the verb, pi in angles, LCM commands refused before anything is sent,
// log-plans refusing the wrong scene, pictures only as .png, the scene's camera remembered by
// the plan file, and CSV export.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "kinograph/lcm/message_convert.h"
#include "kinograph/planning/io/plan_json.h"
#include "kinograph/planning/io/scene.h"
#include "tests/tools/cli_run.h"

namespace kinograph::tools {
namespace {

namespace fs = std::filesystem;

std::string repo(const std::string& path) { return std::string(KINOGRAPH_SOURCE_DIR) + "/" + path; }

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// One rr_reach plan (planned once) in a folder of the test's own.
class CliContract : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("kinograph_cli_polish_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    plan_ = (dir_ / "rr.json").string();
    const CliRun r = run_cli("plan " + repo("robots/scenes/rr_reach.yaml") + " --out " + plan_);
    ASSERT_EQ(r.status, 0) << r.output;
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static fs::path dir_;
  static std::string plan_;
};
fs::path CliContract::dir_;
std::string CliContract::plan_;

TEST_F(CliContract, VersionAndExitCodeTable) {
  const CliRun version = run_cli("--version");
  EXPECT_EQ(version.status, 0);
  EXPECT_EQ(version.output, "kinograph " KINOGRAPH_VERSION "\n");
  const CliRun help = run_cli("--help");
  EXPECT_EQ(help.status, 0);
  for (const char* line :
       {"0   done", "1   bad input", "2   a plan was made", "3   no answer", "64  usage"}) {
    EXPECT_TRUE(contains(help.output, line)) << line << "\n" << help.output;
  }
}

TEST_F(CliContract, EveryUsageErrorHasOneCode) {
  EXPECT_EQ(run_cli("no-such-verb").status, 64);
  EXPECT_EQ(run_cli("plan").status, 64);  // missing scene
  EXPECT_EQ(run_cli("plan " + repo("robots/scenes/rr_reach.yaml") + " --bogus").status, 64);
  EXPECT_EQ(run_cli("").status, 64);  // no verb
  // Bad input is not a usage error.
  EXPECT_EQ(run_cli("plan /no/such/scene.yaml").status, 1);
}

TEST_F(CliContract, GlobalOptionsWorkAfterTheVerb) {
  // The Acrobot's effort="0" warning is a library warning: --log-level error hides it, wherever
  // the option stands.
  const std::string info = "info " + repo("robots/acrobot/acrobot.urdf");
  const CliRun plain = run_cli(info);
  ASSERT_EQ(plain.status, 0) << plain.output;
  ASSERT_TRUE(contains(plain.output, "read as unknown")) << plain.output;
  const CliRun before = run_cli("--log-level error " + info);
  const CliRun after = run_cli(info + " --log-level error");
  EXPECT_EQ(after.status, 0) << after.output;
  EXPECT_FALSE(contains(after.output, "read as unknown")) << after.output;
  EXPECT_EQ(before.output, after.output);
}

TEST_F(CliContract, AnglesMayUsePi) {
  const std::string info = "info " + repo("robots/acrobot/acrobot.urdf") + " --log-level error";
  const CliRun pi = run_cli(info + " --q=pi/2,0");
  const CliRun number = run_cli(info + " --q=1.5707963267948966,0");
  ASSERT_EQ(pi.status, 0) << pi.output;
  EXPECT_EQ(pi.output, number.output);
  EXPECT_TRUE(contains(pi.output, "24.525000 N·m")) << pi.output;
  const CliRun bad = run_cli(info + " --q=pie,0");
  EXPECT_EQ(bad.status, 1);
  EXPECT_TRUE(contains(bad.output, "--q: 'pie' is not a finite number")) << bad.output;
}

// Each of these is refused before LCM is opened: nothing is sent.
TEST_F(CliContract, SendGoalRefusesWhatItCannotFinishBeforeSending) {
  const std::string send = "send-goal --prefix T --lcm-url memq:// ";
  struct Case {
    std::string args, message;
  };
  const std::vector<Case> cases = {
      {"--q 0,0 --wait 1 --out " + (dir_ / "x.json").string(), "--out needs --scene"},
      {"--q 0,0 --out " + (dir_ / "x.json").string() + " --scene " +
           repo("robots/scenes/rr_reach.yaml"),
       "--out needs --wait"},
      {"--q 0,0 --frame tip --position 1,0,0 --quaternion 1,0,0,0", "not both"},
      {"--frame tip --position 1,0,0", "a pose goal needs --frame, --position and --quaternion"},
      {"--q 0,x", "--q: 'x' is not a finite number"},
  };
  for (const Case& c : cases) {
    const CliRun r = run_cli(send + c.args);
    EXPECT_EQ(r.status, 1) << c.args << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, c.message)) << c.args << "\n" << r.output;
    EXPECT_FALSE(contains(r.output, "sent goal")) << c.args << "\n" << r.output;
  }
  EXPECT_FALSE(fs::exists(dir_ / "x.json"));
  // The same goal, complete, is sent (memq: nobody answers, which is fine without --wait).
  const CliRun ok = run_cli(send + "--frame tip --position 1,0,0 --quaternion 1,0,0,0");
  EXPECT_EQ(ok.status, 0) << ok.output;
  EXPECT_TRUE(contains(ok.output, "sent goal")) << ok.output;
}

TEST_F(CliContract, LogPlansRefusesAnotherRobotsSceneAndWritesNothing) {
  // A log with one rr plan on RR_PLAN, written with LCM's own log writer.
  const planning::Scene rr = planning::load_scene(repo("robots/scenes/rr_reach.yaml"));
  const planning::Plan plan = planning::read_plan(plan_, *rr.problem.model);
  const plan_t msg = messages::plan_to_message(plan, *rr.problem.model, "rr", 7, 3,
                                               {plan_t::CLOCK_WALL, 1000, 1000, -1, 1000});
  const std::string log = (dir_ / "rr.lcmlog").string();
  {
    lcm::LogFile file(log, "w");
    ASSERT_TRUE(file.good());
    std::vector<uint8_t> bytes(msg.getEncodedSize());
    msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    lcm::LogEvent event;
    event.eventnum = 0;
    event.timestamp = 1000;
    event.channel = "RR_PLAN";
    event.datalen = static_cast<int32_t>(bytes.size());
    event.data = bytes.data();
    ASSERT_EQ(file.writeEvent(&event), 0);
  }
  const fs::path wrong = dir_ / "wrong";
  const CliRun r = run_cli("log-plans " + log + " --channel RR_PLAN --scene " +
                           repo("robots/scenes/iiwa_desk.yaml") + " --out-dir " + wrong.string());
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "moves joints [joint1, joint2] but the robot of")) << r.output;
  EXPECT_FALSE(fs::exists(wrong));
  const fs::path right = dir_ / "right";
  const CliRun ok = run_cli("log-plans " + log + " --channel RR_PLAN --scene " +
                            repo("robots/scenes/rr_reach.yaml") + " --out-dir " + right.string());
  EXPECT_EQ(ok.status, 0) << ok.output;
  EXPECT_TRUE(fs::exists(right / "plan_3_7.json")) << ok.output;
}

TEST_F(CliContract, PicturesAreWrittenAsPngOnly) {
  const fs::path jpg = dir_ / "strip.jpg";
  const CliRun render = run_cli("render " + plan_ + " --frames 2 --out " + jpg.string());
  EXPECT_EQ(render.status, 64) << render.output;
  EXPECT_TRUE(contains(render.output, "pictures are written as PNG only")) << render.output;
  const CliRun plot = run_cli("plot " + plan_ + " --out " + jpg.string());
  EXPECT_EQ(plot.status, 64) << plot.output;
  EXPECT_FALSE(fs::exists(jpg));
}

TEST_F(CliContract, RenderUsesTheCameraOfTheScenePlanned) {
  // rr_reach with a camera block, planned to a plan file that remembers its scene.
  const fs::path scene = dir_ / "rr_camera.yaml";
  {
    std::ofstream out(scene);
    out << planning::scene_to_yaml(planning::load_scene(repo("robots/scenes/rr_reach.yaml")))
        << "camera: {eye: [0.5, -4, 3], target: [0, 0, 1.2], fov_y_deg: 25}\n";
  }
  const fs::path plan = dir_ / "rr_camera.json";
  ASSERT_EQ(run_cli("plan " + scene.string() + " --out " + plan.string()).status, 0);
  nlohmann::json json = nlohmann::json::parse(read_file(plan));
  ASSERT_TRUE(json.contains("scene"));
  const std::string common = " --frames 2 --width 320 --height 160 --samples 1 --out ";
  const fs::path remembered = dir_ / "remembered.png", given = dir_ / "given.png",
                 automatic = dir_ / "automatic.png";
  ASSERT_EQ(run_cli("render " + plan.string() + common + remembered.string()).status, 0);
  ASSERT_EQ(
      run_cli("render " + plan.string() + " --scene " + scene.string() + common + given.string())
          .status,
      0);
  json.erase("scene");
  const fs::path forgetful = dir_ / "forgetful.json";
  std::ofstream(forgetful) << json.dump();
  ASSERT_EQ(run_cli("render " + forgetful.string() + common + automatic.string()).status, 0);
  EXPECT_EQ(read_file(remembered), read_file(given));
  EXPECT_NE(read_file(remembered), read_file(automatic));
  // A scene the plan names but that is gone: said, and framed automatically.
  json["scene"] = "/no/such/scene.yaml";
  const fs::path orphan = dir_ / "orphan.json";
  std::ofstream(orphan) << json.dump();
  const fs::path framed = dir_ / "framed.png";
  const CliRun r = run_cli("render " + orphan.string() + common + framed.string());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "names scene '/no/such/scene.yaml', which is not found"))
      << r.output;
  EXPECT_EQ(read_file(framed), read_file(automatic));
}

TEST_F(CliContract, ExportWritesThePlanAsCsv) {
  const fs::path csv = dir_ / "rr.csv";
  const CliRun r = run_cli("export " + plan_ + " --csv " + csv.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json json = nlohmann::json::parse(read_file(plan_));
  std::istringstream in(read_file(csv));
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header,
            "t,q:joint1,q:joint2,qd:joint1,qd:joint2,qdd:joint1,qdd:joint2,tau:joint1,tau:joint2");
  std::vector<std::vector<double>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<double> row;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  ASSERT_EQ(rows.size(), json["t"].size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    ASSERT_EQ(rows[k].size(), 9u);
    EXPECT_EQ(rows[k][0], json["t"][k].get<double>());
    EXPECT_EQ(rows[k][1], json["q"][k][0].get<double>());
    EXPECT_EQ(rows[k][2], json["q"][k][1].get<double>());
    EXPECT_EQ(rows[k][8], json["tau"][k][1].get<double>());
  }
}

}  // namespace
}  // namespace kinograph::tools

// `kinograph check-states` judges recorded states: their count, span, the final error to the
// goal and the final speed as written, a clearance from the validator's world, the executed path
// as a plan file with one knot per state; states it cannot read are counted, a log without the
// robot's states and a missing log are refused by name.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "kinograph/robot_state_t.hpp"
#include "tests/lib/temp_dir.h"
#include "tests/tools/cli_run.h"

namespace kinograph::tools {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string> kJoints = {"iiwa_joint_1", "iiwa_joint_2", "iiwa_joint_3",
                                          "iiwa_joint_4", "iiwa_joint_5", "iiwa_joint_6",
                                          "iiwa_joint_7"};
// The desk scene's start and goal (robots/scenes/iiwa_desk.yaml).
const std::vector<double> kStart = {0.801, 1.333, -1.273, -1.753, 0.067, -0.928, -0.188};
const std::vector<double> kGoal = {0.771, 0.335, -0.570, -1.046, -0.686, 0.356, -0.122};

void log_bytes(lcm::LogFile& log, int64_t timestamp, const std::string& channel,
               std::vector<uint8_t> bytes) {
  lcm::LogEvent event;
  event.eventnum = 0;
  event.timestamp = timestamp;
  event.channel = channel;
  event.datalen = static_cast<int32_t>(bytes.size());
  event.data = bytes.data();
  ASSERT_EQ(log.writeEvent(&event), 0);
}

void log_state(lcm::LogFile& log, int64_t utime, const std::string& robot,
               const std::vector<double>& q, double speed) {
  robot_state_t s;
  s.utime = utime;
  s.robot = robot;
  s.num_joints = 7;
  s.joint_name = kJoints;
  s.position = q;
  s.velocity.assign(7, 0.0);
  s.velocity[3] = speed;
  std::vector<uint8_t> bytes(static_cast<std::size_t>(s.getEncodedSize()));
  s.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  log_bytes(log, utime, "IIWA_STATE", std::move(bytes));
}

double value(const std::string& output, const std::string& key) {
  const std::size_t at = output.find("\n" + key + " ");
  EXPECT_NE(at, std::string::npos) << key << " missing in\n" << output;
  return at == std::string::npos ? 0 : std::stod(output.substr(at + key.size() + 2));
}

class CheckStatesTest : public ::testing::Test {
 protected:
  const test_support::TempDir temp_{"kinograph_cli_check_states"};
  const fs::path dir_ = temp_.path();
  const std::string scene_ = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml";
};

TEST_F(CheckStatesTest, JudgesTheRecordedStatesAndWritesTheExecutedPath) {
  const std::string log_path = (dir_ / "states.lcmlog").string();
  {
    lcm::LogFile log(log_path, "w");
    ASSERT_TRUE(log.good());
    log_state(log, 1'000'000, "iiwa14", kStart, 0.0);
    log_bytes(log, 1'002'000, "IIWA_STATE", {1, 2, 3});  // not a state: counted as refused
    log_state(log, 1'005'000, "iiwa14", kStart, 0.0);
    log_state(log, 1'010'000, "iiwa14", kGoal, 0.25);
  }
  const fs::path out = dir_ / "executed.json";
  const CliRun r =
      run_cli("check-states " + log_path + " --scene " + scene_ + " --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string o = "\n" + r.output;
  EXPECT_EQ(value(o, "states"), 3);
  EXPECT_EQ(value(o, "refused"), 1);
  EXPECT_EQ(value(o, "first_utime"), 1'000'000);
  EXPECT_EQ(value(o, "last_utime"), 1'010'000);
  EXPECT_EQ(value(o, "final_goal_error"), 0);  // the last state is the scene's goal
  EXPECT_EQ(value(o, "final_speed"), 0.25);
  EXPECT_GT(value(o, "min_clearance"), 0);  // start and goal are collision-free
  // Against the start as the goal: the last state's largest joint distance to it (joint 6,
  // 0.356 − (−0.928) rad).
  const CliRun g = run_cli("check-states " + log_path + " --scene " + scene_ + " --goal " +
                           "0.801,1.333,-1.273,-1.753,0.067,-0.928,-0.188");
  ASSERT_EQ(g.status, 0) << g.output;
  EXPECT_NEAR(value("\n" + g.output, "final_goal_error"), 0.356 + 0.928, 1e-12);
  // The executed path: one knot per state, times from the first.
  std::ifstream in(out);
  ASSERT_TRUE(in.good()) << r.output;
  const nlohmann::json plan = nlohmann::json::parse(in);
  const std::string text = plan.dump();
  EXPECT_NE(text.find("executed (recorded states)"), std::string::npos);
  EXPECT_NE(text.find("0.01"), std::string::npos) << text.substr(0, 400);
}

TEST_F(CheckStatesTest, RefusesALogWithoutTheRobotsStatesAndAMissingLog) {
  const std::string log_path = (dir_ / "other.lcmlog").string();
  {
    lcm::LogFile log(log_path, "w");
    ASSERT_TRUE(log.good());
    log_state(log, 1'000'000, "acrobot", kStart, 0.0);
  }
  const CliRun r = run_cli("check-states " + log_path + " --scene " + scene_);
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("no robot_state_t of 'iiwa14' on IIWA_STATE"), std::string::npos)
      << r.output;
  const CliRun missing =
      run_cli("check-states " + (dir_ / "none.lcmlog").string() + " --scene " + scene_);
  EXPECT_EQ(missing.status, 1) << missing.output;
  EXPECT_NE(missing.output.find("cannot read LCM log"), std::string::npos) << missing.output;
}

}  // namespace
}  // namespace kinograph::tools

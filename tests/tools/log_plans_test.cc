// `kinograph log-plans` reads the plans of both plan_t versions from an LCM log: a log an
// older kinographd wrote (version 1, no clock) and a current one (version 2, with its clock)
// give plan files alike, and a message on the plan channel that is neither is skipped with a
// message saying so, not taken for a plan. The obstacles a daemon received over LCM in the log
// are in each plan's file as they were when it was published.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/lcmtypes/sample_messages.h"
#include "tests/lib/temp_dir.h"
#include "tests/tools/cli_run.h"

namespace kinograph::tools {
namespace {

namespace fs = std::filesystem;
using namespace kinograph::lcmtypes::testing;


void log_event(lcm::LogFile& log, int64_t timestamp, const std::vector<uint8_t>& bytes,
               const std::string& channel = "IIWA_PLAN") {
  lcm::LogEvent event;
  event.eventnum = 0;
  event.timestamp = timestamp;
  event.channel = channel;
  event.datalen = static_cast<int32_t>(bytes.size());
  event.data = const_cast<uint8_t*>(bytes.data());
  ASSERT_EQ(log.writeEvent(&event), 0);
}

TEST(CliLogPlans, ReadsBothPlanVersionsAndSkipsWhatIsNeither) {
  const kinograph::test_support::TempDir temp("kinograph_cli_log_plans");
  const fs::path& dir = temp.path();
  const std::string log_path = (dir / "mixed.lcmlog").string();
  {
    lcm::LogFile log(log_path, "w");
    ASSERT_TRUE(log.good());
    plan_v1_t old = make_plan_v1(4);
    old.goal_id = 1;
    old.plan_id = 1;
    log_event(log, 1, encode(old));
    plan_t current = make_plan(4);
    current.goal_id = 2;
    current.plan_id = 2;
    log_event(log, 2, encode(current));
    log_event(log, 3, encode(make_planner_status()));  // another type on the plan channel
  }
  const std::string scene = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml";
  const CliRun r = run_cli("log-plans " + log_path + " --channel IIWA_PLAN --scene " + scene +
                       " --out-dir " + (dir / "plans").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "plans" / "plan_1_1.json")) << r.output;
  EXPECT_TRUE(fs::exists(dir / "plans" / "plan_2_2.json")) << r.output;
  EXPECT_NE(r.output.find("plan_t version 1: no clock"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("clock robot, published at 123 us, starts at 5000000 us"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("message at 3 us is not a plan_t of version 2 or 1"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("2 plans written"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("1 of version 1 (no clock)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("1 messages that are not plans skipped"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

// The ids of the obstacles a plan file holds.
std::vector<std::string> obstacle_ids(const fs::path& plan_file) {
  std::ifstream in(plan_file);
  const nlohmann::json j = nlohmann::json::parse(in);
  std::vector<std::string> ids;
  for (const auto& o : j.at("obstacles")) ids.push_back(o.at("id").get<std::string>());
  return ids;
}

// A ball added by "perception" before plan 1 and removed before plan 2: plan 1's file has it
// beside the scene's desk, plan 2's does not; an update that fails its checks is reported.
TEST(CliLogPlans, PlanFilesCarryTheObstaclesReceivedOverLcm) {
  const kinograph::test_support::TempDir temp("kinograph_cli_log_plans");
  const fs::path& dir = temp.path();
  const std::string log_path = (dir / "session.lcmlog").string();
  obstacle_list_t add = make_obstacle_list();
  add.source = "perception";
  add.replace_all = false;
  add.num_obstacles = 1;
  add.obstacles.resize(1);
  obstacle_t& ball = add.obstacles[0];
  ball.id = "ball";
  ball.action = obstacle_t::ADD_OR_MOVE;
  ball.shape = obstacle_t::SPHERE;
  ball.size[0] = 0.1;
  ball.position[0] = 0.5;
  ball.position[1] = 0.0;
  ball.position[2] = 1.0;
  ball.quaternion[0] = 1;
  ball.quaternion[1] = ball.quaternion[2] = ball.quaternion[3] = 0;
  obstacle_list_t remove = add;
  remove.obstacles[0].action = obstacle_t::REMOVE;
  obstacle_list_t bad = add;
  bad.obstacles[0].quaternion[0] = 7;  // not a unit quaternion
  {
    lcm::LogFile log(log_path, "w");
    ASSERT_TRUE(log.good());
    log_event(log, 1, encode(add), "IIWA_OBSTACLES");
    plan_t first = make_plan(4);
    first.goal_id = 1;
    first.plan_id = 1;
    log_event(log, 2, encode(first));
    log_event(log, 3, encode(remove), "IIWA_OBSTACLES");
    log_event(log, 4, encode(bad), "IIWA_OBSTACLES");
    plan_t second = make_plan(4);
    second.goal_id = 1;
    second.plan_id = 2;
    log_event(log, 5, encode(second));
  }
  const std::string scene = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml";
  const CliRun r = run_cli("log-plans " + log_path + " --channel IIWA_PLAN --scene " + scene +
                           " --out-dir " + (dir / "plans").string());
  ASSERT_EQ(r.status, 0) << r.output;
  const std::vector<std::string> first = obstacle_ids(dir / "plans" / "plan_1_1.json");
  const std::vector<std::string> second = obstacle_ids(dir / "plans" / "plan_1_2.json");
  EXPECT_EQ(first.size(), second.size() + 1) << r.output;
  EXPECT_NE(std::find(first.begin(), first.end(), "perception/ball"), first.end()) << r.output;
  EXPECT_EQ(std::find(second.begin(), second.end(), "perception/ball"), second.end());
  EXPECT_NE(r.output.find("2 obstacle updates from IIWA_OBSTACLES applied, 1 not applied"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("message at 4 us not applied"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("not a unit quaternion"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace kinograph::tools

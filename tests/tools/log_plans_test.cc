// `kinograph log-plans` reads the plans of both plan_t versions from an LCM log: a log an
// older kinographd wrote (version 1, no clock) and a current one (version 2, with its clock)
// give plan files alike, and a message on the plan channel that is neither is skipped with a
// message saying so, not taken for a plan.
#include <gtest/gtest.h>

#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "tests/lcmtypes/sample_messages.h"
#include "tests/lib/temp_dir.h"
#include "tests/tools/cli_run.h"

namespace kinograph::tools {
namespace {

namespace fs = std::filesystem;
using namespace kinograph::lcmtypes::testing;


void log_event(lcm::LogFile& log, int64_t timestamp, const std::vector<uint8_t>& bytes) {
  lcm::LogEvent event;
  event.eventnum = 0;
  event.timestamp = timestamp;
  event.channel = "IIWA_PLAN";
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

}  // namespace
}  // namespace kinograph::tools

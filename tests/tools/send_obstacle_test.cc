// `kinograph send-obstacle` names the obstacles' source: the real binary publishes into an LCM
// log (LCM's file:// provider), and the test reads the obstacle_list_t back from the log.
#include <gtest/gtest.h>

#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "lcmtypes/safe_decode.h"
#include "tests/lib/temp_dir.h"
#include "tests/tools/cli_run.h"

namespace kinograph::tools {
namespace {

// The obstacle lists `kinograph send-obstacle <args>` published on RR_OBSTACLES.
std::vector<obstacle_list_t> send(const std::string& args, std::string* output = nullptr) {
  const test_support::TempDir dir("kinograph_send_obstacle");
  const std::string log = (dir / "sent.lcmlog").string();
  const CliRun r =
      run_cli("send-obstacle --prefix RR --lcm-url 'file://" + log + "?mode=w' " + args);
  EXPECT_EQ(r.status, 0) << r.output;
  if (output != nullptr) *output = r.output;
  std::vector<obstacle_list_t> lists;
  lcm::LogFile file(log, "r");
  EXPECT_TRUE(file.good()) << log;
  for (const lcm::LogEvent* e = file.readNextEvent(); e != nullptr; e = file.readNextEvent()) {
    if (e->channel != "RR_OBSTACLES") continue;
    obstacle_list_t list;
    const lcmtypes::DecodeStatus s = lcmtypes::safe_decode(e->data, e->datalen, list);
    EXPECT_TRUE(s.ok) << s.reason;
    if (s.ok) lists.push_back(list);
  }
  return lists;
}

TEST(CliSendObstacle, NamesItsSourceAndCanReplaceThatSourcesObstacles) {
  std::string output;
  const auto lists =
      send("--id ball --shape sphere --size 0.1 --position 0,0,1 --source perception --replace-all",
           &output);
  ASSERT_EQ(lists.size(), 1u);
  EXPECT_EQ(lists[0].source, "perception");
  EXPECT_TRUE(lists[0].replace_all);
  ASSERT_EQ(lists[0].num_obstacles, 1);
  EXPECT_EQ(lists[0].obstacles[0].id, "ball");
  EXPECT_EQ(lists[0].obstacles[0].size[0], 0.1);
  EXPECT_NE(output.find("from source \"perception\" replacing its others"), std::string::npos)
      << output;
}

TEST(CliSendObstacle, WithoutASourceIsTheUnnamedSourcesUpdate) {
  const auto lists = send("--id ball --remove");
  ASSERT_EQ(lists.size(), 1u);
  EXPECT_EQ(lists[0].source, "");
  EXPECT_FALSE(lists[0].replace_all);
  EXPECT_EQ(lists[0].obstacles[0].action, obstacle_t::REMOVE);
}

}  // namespace
}  // namespace kinograph::tools

// StopSignal: a request (also from a signal handler) sets the flag and makes the eventfd
// readable, which is what wakes the node's LCM loop; a node run with it stops on the request.
#include "daemon/stop_signal.h"

#include <gtest/gtest.h>
#include <poll.h>

#include <csignal>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <thread>

#include "daemon/planner_node.h"
#include "kinograph/planning/io/scene.h"

namespace kinograph::daemon {
namespace {

bool readable(int fd) {
  pollfd p{fd, POLLIN, 0};
  return poll(&p, 1, 0) == 1 && (p.revents & POLLIN) != 0;
}

TEST(StopSignal, ARequestSetsTheFlagAndWakesTheFd) {
  StopSignal s;
  EXPECT_FALSE(s.flag().load());
  EXPECT_FALSE(readable(s.fd()));
  s.request();
  EXPECT_TRUE(s.flag().load());
  EXPECT_TRUE(readable(s.fd()));
  s.request();  // a second signal changes nothing
  EXPECT_TRUE(readable(s.fd()));
}

StopSignal* g_signal_target = nullptr;
void on_usr1(int) { g_signal_target->request(); }

TEST(StopSignal, ASignalHandlerCanRequest) {
  StopSignal s;
  g_signal_target = &s;
  auto previous = std::signal(SIGUSR1, on_usr1);
  std::raise(SIGUSR1);  // the handler has run when raise() returns
  std::signal(SIGUSR1, previous);
  EXPECT_TRUE(s.flag().load());
  EXPECT_TRUE(readable(s.fd()));
}

TEST(StopSignal, ANodeRunWithItStopsOnTheRequest) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  PlannerNodeOptions options;
  options.channel_prefix = "RR";
  options.status_period_s = 1000;  // no heartbeat wakes the loop
  planning::Scene scene = planning::parse_scene(
      "name: stop_signal_test\nrobot:\n  urdf: robots/rr/rr.urdf\nhorizon: 2.0\nsteps: 30\n"
      "start:\n  q: [-0.8, 0.4]\ngoal:\n  q: [0.8, -0.4]\n",
      std::string(KINOGRAPH_SOURCE_DIR) + "/scene.yaml");
  PlannerNode node(std::move(scene), options, &lcm);
  StopSignal stop;
  std::thread runner([&] { node.run(stop.flag(), stop.fd()); });
  stop.request();
  runner.join();  // returns: the loop saw the request
  EXPECT_EQ(node.counters().goals_received, 0);
}

}  // namespace
}  // namespace kinograph::daemon

// The executor between the planner and the robot, and its stop request:
//   kinograph execute   SCENE [--prefix IIWA] [--lcm-url URL] [--rate 200]
//   kinograph send-stop --prefix IIWA [--lcm-url URL] [--utime US] [--reason TEXT]
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <iostream>
#include <memory>

#include "execute/executor_node.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/stop_request_t.hpp"
#include "tools/command_registry.h"
#include "tools/lcm_client.h"

namespace kinograph::tools {
namespace {

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

const bool kExecute = register_command([](CLI::App& root) {
  auto* sub = root.add_subcommand(
      "execute",
      "follow the robot's plans: stream <PREFIX>_COMMAND setpoints from <PREFIX>_PLAN on the "
      "clock of <PREFIX>_STATE; stop to rest on <PREFIX>_STOP");
  auto scene = std::make_shared<std::string>();
  auto o = std::make_shared<execution::ExecutorNodeOptions>();
  sub->add_option("scene", *scene, "scene file (robot, payload, obstacles a stop must clear)")
      ->required();
  sub->add_option("--prefix", o->channel_prefix,
                  "channel prefix (default: robot name upper-cased)");
  sub->add_option("--lcm-url", o->lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or udpm)");
  sub->add_option("--rate", o->rate_hz,
                  "setpoints per second of the robot's clock, Hz (default 200: the rate of the "
                  "state stream and of Drake's iiwa driver)");
  sub->callback([=] {
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    // Take-overs and stops are the executor's output; the CLI's default level hides info.
    if (spdlog::get_level() == spdlog::level::warn) spdlog::set_level(spdlog::level::info);
    execution::ExecutorNode node(planning::load_scene(*scene), *o);
    node.run(g_stop);
    const execution::ExecutorCounters& c = node.counters();
    // The largest jump of the commanded motion where one plan replaced another.
    double jump_q = 0, jump_qd = 0;
    long switches = 0;
    for (const execution::Takeover& t : node.takeovers()) {
      if (t.from < 0) continue;
      ++switches;
      jump_q = std::max(jump_q, t.jump_q);
      jump_qd = std::max(jump_qd, t.jump_qd);
    }
    std::cout << "kinograph execute: " << c.plans_accepted << " plans followed, " << c.plans_ignored
              << " ignored, " << c.plans_refused << " refused; " << c.commands << " commands; "
              << c.stops << " stops (" << c.stops_unvalidated
              << " without a valid stopping trajectory); " << switches
              << " take-overs from a plan, largest jump " << jump_q << " rad, " << jump_qd
              << " rad/s\n";
  });
});

const bool kSendStop = register_command([](CLI::App& root) {
  auto* sub = root.add_subcommand("send-stop", "ask the robot's executor to bring it to rest");
  auto prefix = std::make_shared<std::string>();
  auto url = std::make_shared<std::string>();
  auto utime = std::make_shared<int64_t>(0);
  auto reason = std::make_shared<std::string>();
  sub->add_option("--prefix", *prefix, "channel prefix of the robot, e.g. IIWA")->required();
  sub->add_option("--lcm-url", *url, "LCM URL (default: $LCM_DEFAULT_URL or udpm)");
  sub->add_option("--utime", *utime,
                  "the request's time on the robot's clock, µs: plans from states measured "
                  "before it are not followed afterwards (default 0)");
  sub->add_option("--reason", *reason, "why, for the executor's log");
  sub->callback([=] {
    stop_request_t msg;
    msg.utime = *utime;
    msg.request_id = 1;
    msg.reason = *reason;
    open_lcm(*url).publish(*prefix + "_STOP", &msg);
    std::cout << "sent stop request on " << *prefix << "_STOP\n";
  });
});

}  // namespace
}  // namespace kinograph::tools

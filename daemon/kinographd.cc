// kinographd: the kinograph planner daemon for one robot on an LCM network.
//   kinographd SCENE.yaml [--prefix IIWA] [--lcm-url URL] [--status-period 1.0]
//              [--batch-only] [--max-goal-change RAD] [--formulation condensed|dfg]
//              [--ignore-goal-id-gaps] [--max-state-age 0.5] [--takeover-latency 0.3]
//              [--iiwa-status-channel IIWA_STATUS] [--drake-plan-channel COMMITTED_ROBOT_PLAN]
//              [--state-file FILE] [--neighbour NAME=SCENE[@PREFIX] ...]
//              [--neighbour-timeout 3] [--no-neighbour-wait] [--neighbour-yield 5]
// The scene gives the robot, default horizon and steps, start, fixed obstacles, objective
// weights and the batch formulation; goals, obstacle updates and measured states arrive over
// LCM.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <cstdint>
#include <ctime>
#include <iostream>

#include "daemon/planner_node.h"
#include "daemon/stop_signal.h"
#include "kinograph/planning/io/scene.h"

namespace {
kinograph::daemon::StopSignal* g_stop = nullptr;  // set before the handlers are installed
std::atomic<int> g_signal{0};
std::atomic<int64_t> g_signal_ns{0};  // CLOCK_MONOTONIC when the signal came, for the summary
int64_t monotonic_ns() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);  // async-signal-safe, unlike std::chrono's clocks
  return static_cast<int64_t>(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}
void on_signal(int signal) {
  g_signal_ns = monotonic_ns();
  g_signal = signal;
  g_stop->request();  // wakes the node's LCM loop at once
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"kinographd: kinodynamic planner daemon (LCM)"};
  std::string scene_path, level = "info";
  kinograph::daemon::PlannerNodeOptions options;
  app.add_option("scene", scene_path, "scene file (YAML) with the robot and defaults")->required();
  app.add_option("--prefix", options.channel_prefix,
                 "channel prefix (default: robot name upper-cased)");
  app.add_option("--lcm-url", options.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or udpm)");
  app.add_option("--status-period", options.status_period_s, "status heartbeat period (s)")
      ->check(CLI::PositiveNumber);
  app.add_option("--log-level", level, "trace, debug, info, warn, error");
  bool batch_only = false;
  app.add_flag("--batch-only", batch_only,
               "plan every request with a batch solve (no incremental replanning)");
  app.add_option("--max-goal-change", options.replanning.max_incremental_goal_change,
                 "plan joint goals that moved more than this (rad) from scratch (default: never)")
      ->check(CLI::PositiveNumber);
  std::string formulation;  // empty: the scene's planner.formulation
  app.add_option("--formulation", formulation,
                 "batch formulation: condensed (tau = RNEA per step) or dfg (the paper's full "
                 "dynamic factor graph); default: the scene's planner.formulation")
      ->check(CLI::IsMember({"condensed", "dfg"}));
  bool ignore_gaps = false;
  app.add_flag("--ignore-goal-id-gaps", ignore_gaps,
               "goal ids are not numbered 1, 2, 3, ... by one sender: do not answer skipped ids "
               "as lost (default: answer them SUPERSEDED and count them as dropped)");
  app.add_option("--max-state-age", options.max_state_age_s,
                 "refuse a goal (INVALID_STATE) issued more than this many seconds after the "
                 "latest measured state, on the robot's clock")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--takeover-latency", options.takeover_latency_s,
                 "while an executor follows the plans, a replan starts where the motion will be "
                 "this many seconds (robot clock) after the latest state and takes over there; "
                 "set it above the planner's latency (default 0.3)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--iiwa-status-channel", options.iiwa_status_channel,
                 "also read Drake's lcmt_iiwa_status on this channel as the measured state "
                 "(joints in the URDF's order), e.g. IIWA_STATUS; default: none");
  app.add_option("--drake-plan-channel", options.drake_plan_channel,
                 "also publish every valid plan as Drake's lcmt_robot_plan on this channel, "
                 "e.g. COMMITTED_ROBOT_PLAN; default: none");
  app.add_option("--state-file", options.state_file,
                 "remember plan ids and the obstacles received over LCM in this file across "
                 "restarts (written atomically); default: none, plan ids start at 1");
  std::vector<std::string> neighbour_options;
  app.add_option("--neighbour", neighbour_options,
                 "a robot sharing the workspace, NAME=SCENE[@PREFIX] (repeatable): its scene "
                 "file gives its robot, payload and base, PREFIX its channels (default NAME "
                 "upper-cased); planned around as docs/multi_robot.md says");
  app.add_option("--neighbour-timeout", options.neighbour_watch.timeout_s,
                 "a neighbour heard from neither in heartbeats nor in states for this long (s) is "
                 "held still at its last known state and reported (default 3)")
      ->check(CLI::PositiveNumber);
  bool no_wait = false;
  app.add_flag("--no-neighbour-wait", no_wait,
               "answer a goal whose plan runs into a higher-priority neighbour's plan with the "
               "failure, instead of holding the start until that plan ends and planning from "
               "there (default: wait)");
  app.add_option("--neighbour-yield", options.neighbour_yield_s,
                 "before planning, wait while a neighbour of higher priority is making a plan, "
                 "at most this long (s) in all, so that the two are not made at the same moment "
                 "(default 5; 0: do not wait)")
      ->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);
  options.wait_for_neighbours = !no_wait;
  options.answer_goal_id_gaps = !ignore_gaps;
  options.replanning.use_incremental = !batch_only;
  spdlog::set_level(spdlog::level::from_str(level));

  try {
    // Never freed: a signal may still come while the process ends.
    g_stop = new kinograph::daemon::StopSignal();
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    kinograph::planning::Scene scene = kinograph::planning::load_scene(scene_path);
    for (const std::string& text : neighbour_options) {
      options.neighbours.push_back(kinograph::daemon::neighbour_from_option(text));
    }
    // Every batch solve of the node (first plans, fallbacks) is in this formulation.
    const std::string name = formulation.empty() ? scene.planner.formulation : formulation;
    options.replanning.incremental.batch.formulation =
        kinograph::planning::formulation_from_name(name).value();
    spdlog::info("kinographd: batch formulation {}",
                 kinograph::planning::to_string(options.replanning.incremental.batch.formulation));
    kinograph::daemon::PlannerNode node(std::move(scene), options);
    node.run(g_stop->flag(), g_stop->fd());
    const auto c = node.counters();
    if (g_signal != 0) {
      spdlog::info("kinographd: signal {} received; every goal answered {:.1f} ms after it",
                   g_signal.load(), static_cast<double>(monotonic_ns() - g_signal_ns) * 1e-6);
    }
    spdlog::info(
        "kinographd: stopped after {} goals ({} answered, {} superseded, {} cancelled, {} "
        "dropped in transport), {} plans ({} failed, {} incremental replans, {} fallbacks, {} for "
        "neighbours, {} waiting for one, {} after yielding to one), {} rejected messages",
        c.goals_received, c.goals_answered, c.goals_superseded, c.goals_cancelled, c.goals_dropped,
        c.plans_published, c.failures, c.incremental, c.fallbacks, c.neighbour_replans,
        c.neighbour_waits, c.neighbour_yields, c.messages_rejected);
  } catch (const std::exception& e) {
    std::cerr << "kinographd: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

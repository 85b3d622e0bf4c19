#pragma once
// One cell planned by a fleet of real daemons (bench/multi_robot/README.md): one kinographd
// process per arm, the other arms as its neighbours, over LCM; this process sends the goals,
// listens to every channel and measures when the fleet's plans are first clear of each other,
// when the fleet has settled under the coordination rule, the replans and the messages.
#include <nlohmann/json.hpp>
#include <string>

#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"

namespace kinograph::bench {

/// How the fleet is run; the defaults are the benchmark's.
struct FleetRunOptions {
  std::string kinographd;  ///< the daemon's executable
  /// Multicast on the loopback of a private network namespace (ttl 0: never leaves the host).
  std::string lcm_url = "udpm://239.255.76.67:7711?ttl=0&recv_buf_size=8388608";
  double timeout_s = 60;          ///< s from the goals' sending until the problem counts as failed
  double startup_timeout_s = 60;  ///< s for the daemons to start and hear each other
  double status_period_s = 0.2;   ///< the daemons' heartbeat period (s)
  /// The fleet is given up as failed when it has not settled, every daemon is idle and no plan
  /// was published for this long (s): under the rule nobody would replan any more.
  double quiet_s = 3;
  std::string work_dir;  ///< where the arms' scene files and the daemons' logs are written
};

/// Throws std::runtime_error, saying how to run the benchmark, unless a message published on
/// `url` comes back within a second (multicast not routed, e.g. outside a prepared namespace).
void require_multicast(const std::string& url);

/// The cell's robots planned by one daemon each: {success, settled, time_to_mutually_clear_s,
/// time_to_settled_s, replans, neighbour_replans, messages, messages_by_kind, objective,
/// min_clearance, daemons_cpu_s, load1, reason (when it failed), per-arm figures}. Every daemon
/// it started is stopped before it returns or throws.
nlohmann::json run_fleet(const std::string& cell_path, const FleetRunOptions& options);

/// ½Σ‖r‖² of the soft terms of `problem`'s batch graph at `plan`'s trajectory: the objective the
/// planner minimizes, evaluated for any plan of the problem.
double plan_objective(const planning::Problem& problem, const planning::Plan& plan);

}  // namespace kinograph::bench

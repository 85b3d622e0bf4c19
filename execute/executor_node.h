#pragma once
// `kinograph execute`'s core: the executor between a planner and a robot on an LCM network. It
// follows the robot's plans (plan_t on <PREFIX>_PLAN), each from its take-over time on the
// robot's clock (read from robot_state_t on <PREFIX>_STATE), and streams setpoints sampled from
// the plan in force (q, q̇ and the feed-forward τ, joint_command_t on <PREFIX>_COMMAND) at a
// fixed rate of the robot's clock; it holds a plan's last knot once the plan ends, and on a
// stop_request_t (<PREFIX>_STOP) brings the robot to rest on a validated stopping trajectory.
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "kinograph/execution/plan_schedule.h"
#include "kinograph/execution/robot_clock.h"
#include "kinograph/lcm/message_convert.h"
#include "kinograph/planning/io/scene.h"

namespace lcm {
class LCM;
class ReceiveBuffer;
class Subscription;
}  // namespace lcm

namespace kinograph::execution {

/// Options of an ExecutorNode; defaults stream to a robot on the local LCM network.
struct ExecutorNodeOptions {
  /// LCM provider URL; empty = $LCM_DEFAULT_URL, else LCM's default multicast group. Plans of a
  /// 7-dof arm are ~25 kB: on udpm raise the receive buffer (recv_buf_size=4194304).
  std::string lcm_url;
  /// Channel prefix (IIWA for IIWA_PLAN, IIWA_STATE, IIWA_COMMAND, IIWA_STOP); empty = the
  /// robot name upper-cased.
  std::string channel_prefix;
  /// Setpoints per second of the robot's clock (Hz). 200 Hz is the rate of the robot's state
  /// stream and of Drake's iiwa driver (IIWA_COMMAND every 5 ms): a faster stream would carry
  /// setpoints the robot's controllers mostly never see between two of their own cycles.
  double rate_hz = 200;
};

/// What an executor has done since it started (for its log and for tests).
struct ExecutorCounters {
  long plans_accepted = 0;     ///< plan_t queued to take over
  long plans_ignored = 0;      ///< failed plans and plans from before a stop (not errors)
  long plans_refused = 0;      ///< plan_t that did not fit the robot or had no robot clock
  long commands = 0;           ///< joint_command_t published
  long stops = 0;              ///< stop requests carried out
  long stops_unvalidated = 0;  ///< of which no stopping trajectory validated (held in place)
};

/// The executor's node: the scene's robot and world, the plan schedule, the clock and LCM.
class ExecutorNode {
 public:
  /// Throws std::invalid_argument for options out of range (naming the option) and
  /// std::runtime_error when LCM cannot start. `shared`: an LCM instance to use instead of
  /// opening options.lcm_url (in-process tests); it must outlive the node.
  ExecutorNode(planning::Scene scene, ExecutorNodeOptions options, lcm::LCM* shared = nullptr);
  ~ExecutorNode();
  ExecutorNode(const ExecutorNode&) = delete;
  ExecutorNode& operator=(const ExecutorNode&) = delete;

  /// Takes every message that has arrived (plans, states, stop requests), without waiting.
  void handle_pending();
  /// Publishes the setpoint for robot time `utime` (µs), carrying out a stop request first;
  /// false (nothing published) while no plan is in force.
  bool publish_at(int64_t utime);
  /// Streams setpoints at options.rate_hz of the robot's clock (estimated from its states)
  /// until `stop`; nothing is published before the first state and the first plan.
  void run(const std::atomic<bool>& stop);

  /// Full channel name for a suffix, e.g. channel("PLAN") = "IIWA_PLAN".
  std::string channel(const std::string& suffix) const;
  const ExecutorCounters& counters() const { return counters_; }
  /// Every take-over so far, with the jump of the setpoints there.
  const std::vector<Takeover>& takeovers() const { return schedule_.takeovers(); }

 private:
  void on_plan(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void on_state(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void on_stop(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  /// Replaces every plan by a stopping trajectory from the setpoint at `utime`.
  void carry_out_stop(int64_t utime);

  planning::Scene scene_;
  ExecutorNodeOptions options_;
  messages::RobotIdentity identity_;
  PlanSchedule schedule_;
  RobotClock clock_;
  std::unique_ptr<lcm::LCM> owned_lcm_;
  lcm::LCM* lcm_ = nullptr;
  std::vector<lcm::Subscription*> subscriptions_;
  ExecutorCounters counters_;
  std::size_t takeovers_logged_ = 0;
  // A stop request waiting for the next setpoint, and the time of the last one carried out
  // (plans from states measured before it are not followed).
  std::optional<int64_t> pending_stop_;
  int64_t stopped_at_ = -1;
};

}  // namespace kinograph::execution

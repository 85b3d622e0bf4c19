#pragma once
// kinographd's core: one planner for one robot on an LCM network. It listens for goals,
// obstacle updates and measured states, plans off the LCM thread (the newest goal wins), and
// answers every goal with a plan_t — a trajectory, SUPERSEDED when a newer goal was planned
// instead, or a failure status with its reason (docs/reliability.md).
//
// Which plans are incremental replans and what answers a plan that does not validate is the
// planning::Replanner's policy; plan_t.method names the path that answered ("batch",
// "incremental", "batch after incremental", "warm-start", "batch after warm-start").
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "daemon/intake.h"
#include "daemon/log_limiter.h"
#include "daemon/motion_join.h"
#include "daemon/neighbours.h"
#include "daemon/own_heartbeats.h"
#include "daemon/planned_motion.h"
#include "daemon/robot_payload.h"
#include "kinograph/lcm/message_convert.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/replanner.h"

namespace lcm {
class LCM;
class ReceiveBuffer;
class Subscription;
}  // namespace lcm

namespace kinograph::daemon {

// The node takes and answers messages in the LCM conversion's types.
using messages::Check;
using messages::GoalRequest;
using messages::MeasuredState;
using messages::ObstacleKey;
using messages::ObstacleUpdate;
using messages::RobotIdentity;

/// Options of a PlannerNode, with defaults for a robot on the local LCM network.
struct PlannerNodeOptions {
  /// LCM provider URL; empty = $LCM_DEFAULT_URL, else LCM's default multicast group (ttl 0,
  /// so nothing leaves the host). Plans of a 7-dof arm are ~25 kB: on udpm raise the receive
  /// buffer, e.g. "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304".
  std::string lcm_url;
  /// Channel prefix, e.g. "IIWA" for IIWA_GOAL, IIWA_PLAN, ...; empty = the URDF robot name
  /// upper-cased.
  std::string channel_prefix;
  /// Period of the planner_status_t heartbeat (s).
  double status_period_s = 1.0;
  /// The planners and the replanning policy (incremental or batch only, fallbacks).
  planning::ReplannerOptions replanning;
  /// Senders number their goals 1, 2, 3, ...: goal ids skipped between two goals were lost on
  /// the way and are answered SUPERSEDED and counted as dropped. Off when several senders
  /// share the channel or ids are not consecutive (then no id means a loss).
  bool answer_goal_id_gaps = true;
  /// Oldest measured state a goal is planned from (s, robot clock): when the goal's utime is
  /// later than the latest state's by more, the goal is answered INVALID_STATE instead.
  double max_state_age_s = 0.5;
  /// Channel of Drake's lcmt_iiwa_status (e.g. "IIWA_STATUS") read as the measured state too,
  /// joints in the URDF's order; empty = none.
  std::string iiwa_status_channel;
  /// Channel on which every valid plan is also published as Drake's lcmt_robot_plan (e.g.
  /// "COMMITTED_ROBOT_PLAN"); empty = none.
  std::string drake_plan_channel;
  /// File the daemon remembers its plan ids and the obstacles received over LCM in, across
  /// restarts (daemon/state_file.h); empty = none: plan ids start at 1 and those obstacles are
  /// forgotten when it stops.
  std::string state_file;
  /// Expected time (s, robot clock) from the latest state to a replan in the executor's hands:
  /// while an executor follows this daemon's plans, a replan starts where the plan in force is
  /// this long after the latest state, and takes over there (daemon/motion_join.h).
  double takeover_latency_s = 0.3;
  /// Robots sharing the workspace (kinographd --neighbour): planned around under the
  /// coordination rule (docs/multi_robot.md); none by default.
  std::vector<NeighbourSpec> neighbours;
  /// How neighbours are watched (their timeout).
  NeighboursOptions neighbour_watch;
  /// A plan that runs into a higher-priority neighbour's plan is made again with the start held
  /// until that plan ends, and published that much later (docs/multi_robot.md); off: such a goal
  /// is answered with the failure. On by default.
  bool wait_for_neighbours = true;
  /// Before each plan a robot with neighbours announces it in its heartbeat and waits while a
  /// neighbour of higher priority is making a plan, so that the two are not made at the same
  /// moment, each around the other's old one (docs/multi_robot.md, "Yielding"): at most this
  /// long (s) in all, then it plans anyway; 0: no waiting.
  double neighbour_yield_s = 5.0;
};

/// What a node has done since it started (for its status and for tests).
struct NodeCounters {
  int64_t goals_received = 0;      ///< goal_t messages decoded with a goal_id (valid or not)
  int64_t goals_answered = 0;      ///< goals answered once: planned, refused or superseded
  int64_t goals_superseded = 0;    ///< of which SUPERSEDED: a newer goal was planned instead
  int64_t goals_dropped = 0;       ///< goal ids skipped in the sender's sequence (lost), answered
  int messages_rejected = 0;       ///< messages of any type that failed to decode or check
  int plans_published = 0;         ///< plan_t messages sent (successes and failures)
  int failures = 0;                ///< of which not SUCCESS
  int replans = 0;                 ///< plans triggered by an obstacle change for the current goal
  int incremental = 0;             ///< plans answered by an incremental replan (validated or not)
  int fallbacks = 0;               ///< incremental replans redone by a batch solve
  int64_t publish_failures = 0;    ///< messages LCM failed to send (lcm_publish returned non-zero)
  int64_t states_refused = 0;      ///< states beyond the limits or not finite (never a start)
  int64_t foreign_heartbeats = 0;  ///< heartbeats on this daemon's channel published by another
  int64_t goals_cancelled = 0;     ///< goals answered CANCELLED: planning or pending at shutdown
  int64_t joined = 0;              ///< plans that join the motion under way (take over later)
  int64_t late_takeovers = 0;      ///< of which published after their take-over time had passed
  int64_t payload_changes = 0;     ///< payload_t attaches and detaches taken
  int64_t neighbour_replans = 0;   ///< replans because a higher-priority neighbour changed
  int64_t neighbour_waits = 0;     ///< valid plans that hold their start for a neighbour's plan
  int64_t neighbour_yields = 0;    ///< plans begun after waiting for a neighbour's in the making
};

/// The planner daemon's node: scene (robot, defaults, fixed obstacles) + LCM + worker thread.
class PlannerNode {
 public:
  /// LCM's per-subscription queues (liblcm drops, unreported, what arrives beyond them):
  /// sized to absorb a 10 s stall of the node under a 1 kHz goal storm with 200 Hz obstacle
  /// and state streams, bounding what a stall can hold in memory.
  static constexpr int kGoalQueueCapacity = 10000;
  static constexpr int kObstacleQueueCapacity = 2000;
  static constexpr int kStateQueueCapacity = 2000;
  /// Heartbeats read back from the daemon's own status channel (to find a second daemon);
  /// dropping some only delays finding it.
  static constexpr int kHeartbeatQueueCapacity = 100;
  /// Payload changes are rare; each rebuilds the robot.
  static constexpr int kPayloadQueueCapacity = 100;
  /// Own heartbeats remembered to tell them from another daemon's (over an hour at 1 Hz).
  static constexpr std::size_t kOwnHeartbeatMemory = 4096;
  /// Log lines about rejected messages allowed per second and channel; the rest are counted
  /// and summarised in one line.
  static constexpr int kRejectLogLinesPerSecond = 10;
  /// A jump in goal ids larger than this is a new numbering, not a loss.
  static constexpr int64_t kMaxGoalIdGap = kGoalQueueCapacity;
  /// Plan ids reserved in the state file at a time: it is written once per so many plans, and
  /// a restart after a crash skips at most so many ids.
  static constexpr int64_t kPlanIdReservation = 1000;
  /// Least time between two writes of the state file for obstacle changes (s).
  static constexpr double kStateWritePeriod = 1.0;
  /// Longest wait at shutdown for the node's own marker (PREFIX_SHUTDOWN_MARK) to come back
  /// through LCM, for a transport that does not loop a node's messages back (ms).
  static constexpr int kShutdownMarkWait = 500;
  /// How long a robot about to plan listens for its neighbours' announcements of plans in the
  /// making before it looks whom to yield to (ms): longer than a heartbeat takes to arrive.
  static constexpr int kYieldListen = 50;

  /// Throws std::runtime_error naming the URL when LCM cannot start (e.g. no multicast route),
  /// StateFileError when options.state_file exists but cannot be taken (corrupt, foreign).
  /// With `shared`, the node uses that LCM instance instead of opening options.lcm_url (how
  /// in-process tests share one memq:// queue with it); it must outlive the node.
  PlannerNode(planning::Scene scene, PlannerNodeOptions options, lcm::LCM* shared = nullptr);
  ~PlannerNode();
  PlannerNode(const PlannerNode&) = delete;
  PlannerNode& operator=(const PlannerNode&) = delete;

  /// Handles LCM traffic and plans until `stop` becomes true; the planning thread is started
  /// and joined inside. `stop` is seen at once when `wake_fd` (StopSignal::fd()) becomes
  /// readable with it, else within 50 ms. On `stop` a solve under way is cancelled at its next
  /// iteration, and it and every goal still pending are answered CANCELLED.
  void run(const std::atomic<bool>& stop, int wake_fd = -1);

  /// Full channel name for a suffix, e.g. channel("GOAL") = "IIWA_GOAL".
  std::string channel(const std::string& suffix) const;
  NodeCounters counters() const;
  const RobotIdentity& identity() const { return identity_; }

 private:
  void on_goal(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void on_obstacles(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void on_state(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  /// A mesh_obstacle_list_t on the obstacle channel: its meshes resolved and read, then taken
  /// as obstacle changes (LCM thread).
  void on_mesh_obstacles(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  /// A payload_t: the robot rebuilt with the payload (or without) for the plans that follow.
  void on_payload(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  /// Plans with `robot` from now on (worker thread).
  void take_robot(RobotWithPayload robot);
  void on_iiwa_status(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  /// An executor's setpoint: which of this daemon's plans it follows (MotionJoin).
  void on_command(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  /// A heartbeat on this daemon's status channel: its own, or another daemon's (reported).
  void on_heartbeat(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  /// At shutdown: the marker this node sent itself came back (LCM thread).
  void on_shutdown_mark(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  /// At shutdown: handles what LCM received until the marker published with
  /// publish_shutdown_mark() comes back (everything that reached the socket before it has then
  /// been handled), at most kGoalQueueCapacity messages or kShutdownMarkWait.
  void drain_until_mark();
  void publish_shutdown_mark();
  /// Hands a decoded measured state to the intake (LCM thread); one beyond the robot's limits
  /// is refused, and goals are answered INVALID_STATE until a usable state arrives.
  void take_state(const std::string& channel, MeasuredState&& state);
  /// Refuses the newest measured state as a start for `reason` (LCM thread).
  void refuse_state(const std::string& channel, int64_t utime, std::string reason);
  /// Refuses a message that came on `channel`: counted, its reason on the status channel and,
  /// within the rate limit, in the log.
  void reject(const std::string& channel, const std::string& reason);
  /// Publishes `msg` on `channel`; a failure is logged as an error and counted in the heartbeat.
  template <class Message>
  void publish(const std::string& channel, const Message& msg);
  /// Publishes encoded bytes of type `type`, checked as publish() does.
  void publish_bytes(const char* type, const std::string& channel, const void* data, unsigned size);
  /// Logs the summaries of rejections the rate limit left out.
  void flush_reject_log();
  /// Publishes a plan_t without trajectory that answers `goal_id` with a failure status; a
  /// second answer to a goal (a replan's) is not counted as an answered goal again.
  void answer_with_failure(int8_t status, const std::string& reason, int64_t goal_id,
                           bool first_answer = true);
  /// Why a plan for `what` (a goal, an obstacle update), stamped `utime` on the robot's clock,
  /// must not start from `state` (older than max_state_age_s), or empty.
  std::string stale_state_reason(const std::string& what, int64_t utime,
                                 const MeasuredState& state) const;
  /// Answers the goals a newer one replaced and the ids that never arrived (worker thread).
  void answer_superseded(const Intake& taken);
  /// Hands what the handlers took off LCM to the worker, in one go (LCM thread).
  void hand_over();
  void worker_loop(const std::atomic<bool>& stop);
  /// Answers the goals `taken` holds at shutdown: replaced ones SUPERSEDED, the newest
  /// CANCELLED; its obstacle changes are applied, not planned (worker thread, or run() once
  /// the worker has ended).
  void answer_at_shutdown(const Intake& taken);
  /// Applies obstacle changes in order after emptying each replaced source; true when the
  /// world changed (worker thread).
  bool apply_obstacles(const std::vector<ObstacleUpdate>& updates,
                       const std::set<std::string>& replaced_sources);
  /// Copies the LCM obstacles for the state file (worker thread, after a change).
  void store_obstacles();
  /// Writes the state file when obstacles changed and the last write is kStateWritePeriod
  /// old (worker thread).
  void save_state_if_due();
  /// Plans `goal` and publishes the answer; `trigger_utime` is the robot-clock time of what
  /// made it plan (the goal, or for a replan the obstacle update), for the state's age.
  void plan_and_publish(const GoalRequest& goal, bool replan, int64_t trigger_utime);
  /// Before planning `goal`: announces the plan in the making and waits while a neighbour of
  /// higher priority is making one, at most options_.neighbour_yield_s (worker thread).
  void yield_to_neighbours(const GoalRequest& goal);
  void publish_status();
  /// Replans the current goal when the coordination rule says a neighbour's change calls for
  /// it (worker thread).
  void replan_for_neighbours();
  /// Answers the current goal again, as a deadlock, when its failure was a neighbour held at its
  /// state that now reports being blocked by this robot (worker thread).
  void answer_deadlock();
  /// Sends the current valid plan again on PREFIX_PLAN_CURRENT, for a neighbour that joined
  /// after it was published (worker thread).
  void republish_current_plan();
  /// Takes the next plan id; first writes a new reservation to the state file when the
  /// reserved ids run out. Caller holds mutex_.
  int64_t take_plan_id_locked();
  /// Loads options.state_file, if it exists, into the plan ids and the LCM obstacles.
  void restore_state();
  /// Writes the state file (no-op without one); a failure is logged as an error. Caller holds
  /// mutex_.
  void save_state_locked();
  /// The wall clock (epoch, µs): the heartbeat's, and the plans' while no state has arrived.
  static int64_t wall_utime();
  /// The plans' clock: the latest measured state's utime, or the wall clock before any state
  /// arrived. Caller holds mutex_.
  messages::PlanTime clock_now_locked() const;

  planning::Scene scene_;
  PlannerNodeOptions options_;
  RobotIdentity identity_;
  std::unique_ptr<lcm::LCM> owned_lcm_;
  lcm::LCM* lcm_ = nullptr;
  std::vector<lcm::Subscription*> subscriptions_;

  // Owned by the LCM thread: what its handlers took off LCM since the last hand-over, so that
  // a burst is handed to the worker whole (the newest goal of it planned, not the first).
  Intake intake_;
  GoalIdSequence goal_ids_{kMaxGoalIdGap};

  // Shared between the LCM thread and the worker, under mutex_.
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  Intake pending_;
  std::optional<MeasuredState> latest_state_;
  std::uint64_t state_count_ = 0;  // measured states received; compared with used_state_count_
  NodeCounters counters_;
  int8_t state_ = 0;  // planner_status_t::IDLE / PLANNING / ERROR
  int64_t planning_goal_utime_ = -1;  // while PLANNING: the utime of the goal being planned
  int64_t last_goal_id_ = -1;
  int64_t last_plan_id_ = -1;
  std::string last_message_;
  std::string last_publish_failure_;  // channel of the last failed publish
  std::string state_refusal_;         // why the newest measured state cannot be a start, or empty
  LogLimiter reject_log_{kRejectLogLinesPerSecond, 1.0};
  OwnHeartbeats own_heartbeats_{kOwnHeartbeatMemory};
  std::string foreign_daemon_;        // what the last foreign heartbeat said about its daemon
  int64_t foreign_logged_utime_ = 0;  // wall clock of the last log line about it
  int64_t next_plan_id_ = 1;
  int64_t plan_ids_reserved_ = 1;  // ids below this are in the state file's reservation
  // Copy of the LCM obstacles for the state file, taken by the worker after each change.
  std::map<ObstacleKey, ObstacleUpdate> stored_obstacles_;
  bool stored_obstacles_dirty_ = false;
  std::chrono::steady_clock::time_point state_written_at_{};
  // Set when run() ends: the worker's solver loops poll it (graph/cancellation.h).
  std::atomic<bool> cancel_{false};
  // The shutdown marker: this node's address and pid, so that another daemon's is not taken.
  std::string shutdown_mark_;
  lcm::Subscription* shutdown_mark_subscription_ = nullptr;
  bool shutdown_mark_seen_ = false;
  MotionJoin motion_join_;  // the newest valid plan and the executor following it
  // Without states, a robot with neighbours is where its valid plans have it (worker thread).
  PlannedMotion planned_motion_;
  std::optional<RobotWithPayload> pending_robot_;  // after a payload_t, not yet taken
  // What the heartbeat tells neighbours: the model's id, the current valid plan and its goal.
  std::string model_id_;
  int64_t valid_plan_id_ = -1;
  int64_t valid_goal_utime_ = -1;
  std::unique_ptr<Neighbours> neighbours_;  // null without neighbours
  std::optional<plan_t> current_plan_msg_;  // the last SUCCESS plan_t sent (worker thread)

  // Owned by the worker thread.
  std::map<ObstacleKey, collision::Obstacle> live_obstacles_;  // by (source, id)
  int next_obstacle_id_ = 0;
  std::optional<GoalRequest> current_goal_;
  std::optional<RobotWithPayload> robot_;  // the robot since the last payload_t; unset: the scene's
  planning::Replanner replanner_;
  // The current goal's failure when a neighbour held at its state blocked it: a deadlock once
  // that neighbour says this robot blocks it.
  struct BlockedAnswer {
    int64_t goal_id;
    std::string name, prefix, why;
  };
  std::optional<BlockedAnswer> blocked_;
  std::uint64_t used_state_count_ = 0;  // state_count_ when the planner's start was last set
};

}  // namespace kinograph::daemon

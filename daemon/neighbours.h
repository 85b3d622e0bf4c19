#pragma once
// The robots a daemon shares its workspace with: their plans, states and heartbeats heard on
// their channels, turned into obstacles of this robot's planner under the coordination rule
// (kinograph/fleet/coordination.h, docs/multi_robot.md). Handlers run on the LCM thread, the rest
// on the planner's worker; one mutex guards what both see.
#include <Eigen/Geometry>
#include <chrono>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "kinograph/collision/obstacle.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/fleet/coordination.h"
#include "kinograph/planning/plan.h"

namespace lcm {
class LCM;
class ReceiveBuffer;
class Subscription;
}  // namespace lcm

namespace kinograph::daemon {

/// One neighbour as this daemon's configuration names it.
struct NeighbourSpec {
  std::string name;            ///< its name in reasons and the status, e.g. "right"
  std::string channel_prefix;  ///< its channels PREFIX_PLAN, _STATE, _PLANNER_STATUS
  /// Its robot placed at its base, payload attached (from its scene file).
  std::shared_ptr<const dynamics::Model> model;
  Eigen::Isometry3d base = Eigen::Isometry3d::Identity();  ///< where its scene puts its base
  /// Its scene's start: where it stands until a state or plan of it is heard (empty: nowhere).
  Eigen::VectorXd start_q;
};

/// Reads kinographd's `--neighbour NAME=SCENE[@PREFIX]`: the neighbour's own scene file gives its
/// robot, payload and base; PREFIX defaults to NAME upper-cased.
/// @throws std::invalid_argument naming the option text, or the scene's SceneError.
NeighbourSpec neighbour_from_option(const std::string& text);

/// How neighbours are watched.
struct NeighboursOptions {
  /// A neighbour heard from neither in heartbeats nor in states for this long (s, wall clock)
  /// is silent: held still at its last known state and reported. Default 3 s, three heartbeats
  /// of the default period.
  double timeout_s = 3.0;
};

/// The neighbours of one daemon.
class Neighbours {
 public:
  /// At most kMaxNeighbours neighbours of at most kMaxBodies collision geometries each.
  static constexpr int kMaxNeighbours = 16;
  static constexpr int kMaxBodies = 64;
  /// Obstacle ids of neighbour bodies start here, far above the scene's and LCM's.
  static constexpr int kFirstObstacleId = 1 << 28;

  /// `own_prefix` is this robot's channel prefix: its name in the priority order. Throws
  /// std::invalid_argument for a neighbour without model, beyond the limits, or named twice.
  Neighbours(std::vector<NeighbourSpec> specs, std::string own_prefix, NeighboursOptions options);

  /// Subscribes to every neighbour's PLAN, PLAN_CURRENT (its current plan again, for a robot
  /// that joined late), STATE and PLANNER_STATUS channels; `changed` is called
  /// (LCM thread) whenever what the rule sees may have changed. The LCM must outlive this.
  void subscribe(lcm::LCM& lcm, std::function<void()> changed);
  /// Unsubscribes (before the LCM goes).
  void unsubscribe(lcm::LCM& lcm);

  /// True once since the last call when a neighbour's plan, priority or liveness changed (a
  /// silence found here counts). Worker thread.
  bool take_changed();
  /// The rule's decision for this robot (priority key `own`) now; a changed own goal forgets the
  /// previous goal's refusal and retries.
  fleet::Decision decide(const fleet::PriorityKey& own, bool own_goal_changed);
  /// Appends every neighbour's bodies as the decision treats them, timed from `origin_utime`
  /// (the own plan's knot 0 on the common clock; a neighbour held still is held as then), to
  /// `obstacles`.
  void add_obstacles(const fleet::Decision& decision, std::int64_t origin_utime,
                     std::vector<collision::Obstacle>& obstacles);
  /// The neighbour, not silent, whose heartbeat says it is making a plan for a goal that
  /// outranks this robot's goal of `own_goal_utime` (fleet::outranks on its
  /// planning_goal_utime and prefix): this robot yields to it before planning; empty when none.
  std::string planning_above(std::int64_t own_goal_utime) const;
  /// True once when a neighbour was heard for the first time or after being silent (a started
  /// or restarted daemon, which has missed this robot's current plan). Worker thread.
  bool take_joined();
  /// The neighbour, as `decision` treats it, that `plan` (own clock: knot 0 at `origin_utime`
  /// plus `wait_s`, standing at its first knot before and its last after) comes within `contact`
  /// metres of, from own-clock time `from_s` on: the closest such one, with `why` saying where;
  /// none when it keeps clear of all. `from_s` is 0 for a plan from a measured state (what came
  /// before is another motion), `wait_s` for one from the own plans in force (they move the robot
  /// until it starts), and −∞ for the first one from no state, whose robot has stood at its first
  /// knot all along, so a followed plan that passed through it before counts. A neighbour held
  /// still is held as at the plan's start, `origin_utime` plus `wait_s`. Worker thread.
  std::optional<fleet::Blocker> blocker(const fleet::Decision& decision, std::int64_t origin_utime,
                                        const dynamics::Model& own_model,
                                        const planning::Plan& plan, double wait_s, double contact,
                                        double from_s, std::string& why) const;
  /// When neighbour `name`'s latest heartbeat reports a failure blocked by this robot, directly
  /// or through neighbours each blocked by the next (a cycle): the channel prefixes from it on,
  /// the last one blocked by this robot (fleet::Blocker::cycle); empty otherwise.
  std::vector<std::string> blocking_cycle(const std::string& name) const;
  /// Records that the current goal was planned as `decision` says, `valid` or not: what later
  /// changes are judged by, and for a valid plan what the heartbeat reports as followed.
  /// `refused_by` is the neighbour that blocked it when its answer is that failure (tried again
  /// once that neighbour has a new plan), null otherwise.
  void planned(const fleet::Decision& decision, bool valid, const fleet::Blocker* refused_by);
  /// `text` with "obstacle <id>" of a neighbour body replaced by its name ("neighbour 'right'
  /// link 'iiwa_link_4'").
  std::string name_bodies(std::string text) const;
  /// One entry per neighbour for the heartbeat, "; "-separated: how it is seen ("right: plan 3,
  /// followed" when the current valid plan was made around its plan 3; "right: plan 3, held at
  /// its state"; "silent for 4.1 s, held at its last state"; a model or base mismatch in
  /// brackets).
  std::string summary() const;
  /// Number of neighbours.
  std::size_t size() const { return specs_.size(); }

 private:
  struct Heard {
    std::optional<planning::Plan> plan;  // its newest valid plan
    std::int64_t plan_start_utime = 0;
    std::int64_t generation = 0;  // local count of the valid plans received (ids may restart)
    std::int64_t plan_id = -1;    // as the neighbour numbers it
    std::optional<Eigen::VectorXd> state;
    std::int64_t state_utime = 0;  // its measurement time on the common clock
    std::int64_t goal_utime = std::numeric_limits<std::int64_t>::max();
    std::string mismatch;    // why its heartbeat does not fit the scene, or empty
    std::string blocked_by;  // prefix its latest failure names as blocker (fleet::blocker_prefix)
    std::int64_t planning_goal_utime = -1;  // goal utime of its plan in the making; -1 none
    std::optional<std::chrono::steady_clock::time_point> last_heard;
    bool silent = false;
  };
  void on_plan(std::size_t i, const lcm::ReceiveBuffer* rbuf);
  void on_state(std::size_t i, const lcm::ReceiveBuffer* rbuf);
  void on_heartbeat(std::size_t i, const lcm::ReceiveBuffer* rbuf);
  // Where neighbour i stands when held still at common-clock time `utime`: its latest state,
  // else where its latest plan has it then, else its scene's start; none without any. Caller
  // holds mutex_.
  std::optional<Eigen::VectorXd> held_q_locked(std::size_t i, std::int64_t utime) const;
  // Its plan to move along, when the decision follows it: none once a measured state newer than
  // the plan's end says where the robot is now. Caller holds mutex_.
  const planning::Plan* followed_plan_locked(const fleet::Decision& decision, std::size_t i) const;
  // blocking_cycle of neighbour i. Caller holds mutex_.
  std::vector<std::string> blocking_cycle_locked(std::size_t i) const;
  // Marks neighbours silent after the timeout; true when one became silent. Caller holds mutex_.
  bool update_silence_locked();
  void notify();
  // One subscription's target: which neighbour, which handler.
  struct Route {
    Neighbours* self;
    std::size_t index;
    void (Neighbours::*handler)(std::size_t, const lcm::ReceiveBuffer*);
  };

  std::vector<NeighbourSpec> specs_;
  std::vector<std::string> model_ids_;
  std::string own_prefix_;
  NeighboursOptions options_;
  std::function<void()> changed_callback_;
  std::vector<lcm::Subscription*> subscriptions_;
  std::vector<std::unique_ptr<Route>> routes_;

  mutable std::mutex mutex_;
  std::vector<Heard> heard_;
  bool changed_ = false;
  bool joined_ = false;
  fleet::PlannedAround planned_;  // what the current valid plan was made around
  fleet::PlannedAround tried_;    // what the latest plan, valid or not, was made around
  std::optional<fleet::BlockedGoal> blocked_goal_;  // the current goal's refusal by a neighbour
  int goal_retries_ = 0;                            // retries of the current goal for blockers
  std::int64_t rebuilds_ = 0;              // obstacle sets made (moving bodies get new ids)
  std::map<int, std::string> body_names_;  // obstacle id -> name, of the last set made
};

}  // namespace kinograph::daemon

#pragma once
// The coordination rule of robots that plan around each other (docs/multi_robot.md): who yields
// to whom, how each neighbour is treated, and when a robot replans. Pure functions, no I/O.
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace kinograph::fleet {

/// What orders robots: the utime of the goal its current plan answers (earlier = higher
/// priority), then its name. A robot without a goal has the latest possible utime.
struct PriorityKey {
  std::int64_t goal_utime = std::numeric_limits<std::int64_t>::max();
  std::string robot;
};

/// True when `a` has priority over `b`: an earlier goal, or the same goal time and a name that
/// sorts first. A strict total order on robots of different names.
bool outranks(const PriorityKey& a, const PriorityKey& b);

/// How a robot plans around one neighbour.
enum class Treatment {
  kAlongPlan,   ///< a neighbour with a plan in force: its bodies move along that plan
  kHeldAtState  ///< a silent or planless neighbour: held still at its state
};

/// "along plan" or "held at state".
std::string to_string(Treatment treatment);

/// What a robot knows of one neighbour when it decides.
struct NeighbourView {
  std::string name;
  PriorityKey key;                      ///< from its heartbeat
  std::optional<std::int64_t> plan_id;  ///< its current valid plan; none without one
  bool silent = false;  ///< nothing heard within the neighbour timeout: held at its last state
};

/// What the robot's current plan was planned around: per neighbour the plan id followed, or
/// kHeldMark when it was held at a state.
using PlannedAround = std::map<std::string, std::int64_t>;
/// The PlannedAround entry of a neighbour held at a state.
inline constexpr std::int64_t kHeldMark = -1;

/// A current goal whose latest answer is a failure because neighbour `neighbour` blocked it:
/// what is needed to try it again once that neighbour moves (docs/multi_robot.md, "Trying again").
struct BlockedGoal {
  std::string neighbour;                ///< the blocker's name
  std::optional<std::int64_t> plan_id;  ///< the blocker's plan when the goal was tried; none
  int retries = 0;                      ///< retries of this goal so far
};

/// Retries of one goal for blocking neighbours' new plans: a small bound on top of the rule's.
inline constexpr int kMaxBlockedRetries = 3;

/// What the rule says now.
struct Decision {
  std::vector<Treatment> treatment;  ///< one per neighbour, in the order given
  bool replan = false;               ///< plan again around the neighbours as treated
  /// The replan tries a blocked goal again: its blocker is followed along its new plan, whatever
  /// its priority (counts against kMaxBlockedRetries).
  bool retry = false;
  std::string reason;    ///< why (or why not), in the user's terms
  PlannedAround around;  ///< what a plan made now is planned around (store it when replanning)
  /// Each neighbour's plan id as seen now (none without one), in the order given.
  std::vector<std::optional<std::int64_t>> plans;
};

/// The rule: neighbours with a plan in force are followed along it, the others held at their
/// state; replan when the own goal changed or a neighbour's entry in `around` would differ
/// from what `planned` says for a higher-priority neighbour (a new plan, a neighbour gone silent
/// or newly higher), never for a change of a lower-priority one. `planned` is what the latest
/// attempt at the goal was planned around (valid or not), empty before the first. With
/// `blocked` (the current goal refused because that neighbour blocked it) and the own goal
/// unchanged: when the blocker, not silent, has a plan other than `blocked->plan_id` and fewer
/// than kMaxBlockedRetries retries were made, replan once more with it followed along that plan.
Decision coordinate(const PriorityKey& own, const std::vector<NeighbourView>& neighbours,
                    const PlannedAround& planned, bool own_goal_changed,
                    const BlockedGoal* blocked = nullptr);

/// When a yielding robot has no way around a neighbour: wait with its start held until the
/// neighbour's plan ends, then move.
struct WaitPlan {
  double wait = 0;     ///< s the start is held (0: the neighbour's plan has ended already)
  double horizon = 0;  ///< s: the own motion's horizon plus the wait
};

/// The wait for a blocking plan ending at `blocking_end` (own clock, s) when the own plan would
/// start at `own_start` with `horizon` s of motion.
WaitPlan wait_for(double blocking_end, double own_start, double horizon);

/// The neighbour a plan ran into (its bodies, as the rule treated them, within contact of the
/// plan's), and what is known of it.
struct Blocker {
  std::string name;    ///< its name in this robot's configuration
  std::string prefix;  ///< its channel prefix: its name in the priority order and in reasons
  Treatment treatment = Treatment::kHeldAtState;
  /// Own-clock time (s) at which its plan ends: the followed plan (kAlongPlan), or the plan in
  /// force of a held neighbour that moves along it (`moving`).
  double plan_end = 0;
  /// Its own latest answer is a failure blocked by this robot (blocker_prefix of its reason),
  /// directly or through neighbours each blocked by the next.
  bool blocked_by_own = false;
  /// With blocked_by_own: the channel prefixes from it on, each robot blocked by the next and
  /// the last by this robot ({"B"} when it is blocked by this robot itself).
  std::vector<std::string> cycle;
  /// kHeldAtState: it has no measured state and moves along its plan in force until `plan_end`,
  /// where it is held after a wait (a lower-priority robot already under way).
  bool moving = false;
};

/// What a robot whose plan ran into a neighbour does.
struct Remedy {
  enum class Kind {
    kWait,      ///< plan again with the start held for `wait.wait` s: the blocking plan ends then
    kFail,      ///< answer the goal with a failure, `reason`
    kDeadlock,  ///< answer with a failure, `reason`: the two robots block each other
  };
  Kind kind = Kind::kFail;
  WaitPlan wait;
  std::string reason;
};

/// The rule for a blocked plan (docs/multi_robot.md). Blocked by a followed neighbour's plan, or
/// by a held neighbour moving along its plan in force, that ends after `own_start` (own clock,
/// s; the wait already taken, 0 for none), and `no_wait` empty: wait until it ends. Blocked by
/// it after waiting, or with `no_wait` saying why the robot may not wait: fail. Blocked by a
/// neighbour held at its state that is itself blocked by this robot: deadlock. Otherwise fail. `own` is this robot's channel prefix, `why` what the planner
/// or the check found.
Remedy remedy(const std::string& own, const Blocker& blocker, double own_start, double horizon,
              const std::string& no_wait, const std::string& why);

/// What a plan that waits says (its status message, the heartbeat): "starts 3.000 s late: waits
/// for neighbour 'a''s plan to end".
std::string wait_note(const std::string& neighbour, double wait);

/// The failure reason of a plan blocked by neighbour `name` (channel prefix `prefix`) as
/// `treatment` says, e.g. "blocked by neighbour 'b' [B], held at its state: ..."; after
/// `waited` s of waiting (0: none), it says so.
std::string blocked_reason(const std::string& name, const std::string& prefix, Treatment treatment,
                           double waited, const std::string& why);

/// The FAILED reason of a deadlock of robot `own` (its prefix) and neighbour `name` (`prefix`):
/// each is held where the other must go, so neither can move first. With `cycle` (Blocker::cycle)
/// of more than one robot, the cycle own → B → C → own is named instead: each where the next
/// must go.
std::string deadlock_reason(const std::string& own, const std::string& name,
                            const std::string& prefix, const std::string& why,
                            const std::vector<std::string>& cycle = {});

/// The channel prefix of the neighbour that blocked a plan, as blocked_reason or deadlock_reason
/// wrote it into `reason` (a failure answer, a heartbeat's message); empty when none.
std::string blocker_prefix(const std::string& reason);

}  // namespace kinograph::fleet

#pragma once
// What the daemon has taken off LCM and not yet handed to its planner, and the goal-id
// bookkeeping that finds goals LCM or the network lost. The LCM thread fills an Intake without
// blocking on the planner; the worker takes it whole, answers every superseded or lost goal and
// plans only the newest one.
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "kinograph/lcm/message_convert.h"

namespace kinograph::daemon {

/// Goal ids first..last (inclusive) that never arrived, found missing when goal `revealed_by`
/// did.
struct LostGoals {
  int64_t first = 0;
  int64_t last = 0;
  int64_t revealed_by = 0;
  /// How many ids never arrived.
  int64_t count() const { return last - first + 1; }
};

/// Messages received but not yet planned, coalesced: the newest valid goal, the goals it
/// replaced (each to be answered SUPERSEDED), goal ids found missing, the obstacle changes in
/// arrival order and the latest measured state.
struct Intake {
  std::optional<messages::GoalRequest> goal;
  std::vector<int64_t> superseded;
  std::vector<LostGoals> lost;
  std::vector<messages::ObstacleUpdate> obstacles;
  /// Sources whose obstacles the changes start from nothing (a replace_all of theirs).
  std::set<std::string> replaced_sources;
  int64_t obstacles_utime = -1;  ///< newest obstacle_list_t.utime (robot clock), -1 = none
  std::optional<messages::MeasuredState> state;
  std::uint64_t states = 0;  ///< measured states received
  /// Why the newest measured state was refused as a start (beyond the limits), or empty when
  /// the newest one is `state`.
  std::string state_refused;

  /// Nothing arrived.
  bool empty() const;
  /// Adds what arrived after this intake: a newer goal supersedes the one held here, a
  /// replace_all discards the changes of its source held here, a newer state, usable or refused,
  /// replaces the old one.
  void absorb(Intake&& newer);
};

/// Goal ids as one sender numbers them (1, 2, 3, ...): finds the ids skipped between two
/// consecutive goals. A jump of more than `max_gap` ids, or a step back, is taken as a new
/// numbering (a restarted or another sender), not as a loss.
class GoalIdSequence {
 public:
  explicit GoalIdSequence(int64_t max_gap) : max_gap_(max_gap) {}
  /// Records the goal `id` just received; returns the ids skipped since the previous goal.
  std::optional<LostGoals> next(int64_t id);

 private:
  int64_t max_gap_;
  int64_t last_ = -1;
};

}  // namespace kinograph::daemon

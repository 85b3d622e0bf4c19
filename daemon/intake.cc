#include "daemon/intake.h"

#include <algorithm>
#include <iterator>
#include <utility>

namespace kinograph::daemon {

bool Intake::empty() const {
  return !goal && superseded.empty() && lost.empty() && obstacles.empty() &&
         replaced_sources.empty() && states == 0 && state_refused.empty();
}

void Intake::absorb(Intake&& newer) {
  if (newer.goal) {
    if (goal) superseded.push_back(goal->goal_id);
    goal = std::move(newer.goal);
  }
  superseded.insert(superseded.end(), newer.superseded.begin(), newer.superseded.end());
  lost.insert(lost.end(), newer.lost.begin(), newer.lost.end());
  for (const std::string& source : newer.replaced_sources) {
    std::erase_if(obstacles, [&](const messages::ObstacleUpdate& u) { return u.source == source; });
    replaced_sources.insert(source);
  }
  obstacles.insert(obstacles.end(), std::make_move_iterator(newer.obstacles.begin()),
                   std::make_move_iterator(newer.obstacles.end()));
  obstacles_utime = std::max(obstacles_utime, newer.obstacles_utime);
  if (newer.state) {
    state = std::move(newer.state);
    state_refused.clear();
  }
  if (!newer.state_refused.empty()) state_refused = std::move(newer.state_refused);
  states += newer.states;
}

std::optional<LostGoals> GoalIdSequence::next(int64_t id) {
  const int64_t previous = last_;
  last_ = id;
  if (previous < 0 || id <= previous + 1 || id - previous - 1 > max_gap_) return std::nullopt;
  return LostGoals{previous + 1, id - 1, id};
}

}  // namespace kinograph::daemon

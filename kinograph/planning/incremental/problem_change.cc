#include "kinograph/planning/incremental/problem_change.h"

#include <algorithm>

namespace kinograph::planning {

std::string apply_change(const Problem& problem, const ProblemChange& change, Problem& next,
                         std::set<int>& changed_obstacles) {
  next = problem;
  if (change.goal) next.goal = *change.goal;
  if (change.start_q) next.start_q = *change.start_q;
  if (change.start_qd) next.start_qd = *change.start_qd;
  if (change.horizon) next.horizon = *change.horizon;
  changed_obstacles.clear();
  for (int id : change.remove) {
    const auto it = std::find_if(next.obstacles.begin(), next.obstacles.end(),
                                 [id](const collision::Obstacle& o) { return o.id == id; });
    if (it == next.obstacles.end()) return "no obstacle with id " + std::to_string(id) + " to remove";
    next.obstacles.erase(it);
    changed_obstacles.insert(id);
  }
  for (const collision::Obstacle& o : change.add_or_move) {
    const auto it = std::find_if(next.obstacles.begin(), next.obstacles.end(),
                                 [&o](const collision::Obstacle& x) { return x.id == o.id; });
    if (it != next.obstacles.end()) {
      *it = o;
    } else {
      next.obstacles.push_back(o);
    }
    changed_obstacles.insert(o.id);
  }
  return "";
}

}  // namespace kinograph::planning

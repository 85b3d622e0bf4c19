#pragma once
// A change of a planning problem (new goal, measured start, horizon, obstacles added, moved or
// removed) and the changed problem it gives.
#include <Eigen/Core>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "kinograph/collision/obstacle.h"
#include "kinograph/planning/problem.h"

namespace kinograph::planning {

/// A change of the problem; everything set is applied in one replan.
struct ProblemChange {
  std::optional<Goal> goal;                          ///< new goal (joint or pose)
  std::optional<Eigen::VectorXd> start_q, start_qd;  ///< measured robot state (re-anchor)
  std::optional<double> horizon;                     ///< new end time (s), same step count
  std::vector<collision::Obstacle> add_or_move;      ///< by id: new ids are added, others replaced
  std::vector<int> remove;                           ///< obstacle ids to remove
};

/// `problem` with `change` applied; the ids of the obstacles it adds, moves or removes go to
/// `changed_obstacles`. Returns the reason when the change cannot apply (an unknown id to
/// remove), else an empty string; the changed problem is not checked here.
std::string apply_change(const Problem& problem, const ProblemChange& change, Problem& next,
                         std::set<int>& changed_obstacles);

}  // namespace kinograph::planning

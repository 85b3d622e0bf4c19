#pragma once
// A collision-free joint-space path for the batch planner's initial trajectory: a seeded
// bidirectional RRT (RRT-Connect, Kuffner and LaValle 2000) over the problem's clearance world
// (obstacles, floor, self pairs), then shortcut. The factor graph polishes the path it seeds;
// nothing here judges a plan.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "kinograph/planning/problem.h"

namespace kinograph::planning {

/// Options of search_path.
struct PathSearchOptions {
  /// Random configurations drawn before giving up (0 = never search).
  int max_samples = 5000;
  /// m, clearance from the obstacles every checked configuration of the path keeps (less only
  /// where the start or goal themselves are closer); LM then widens it to the planner's ε.
  double obstacle_clearance = 0.02;
  std::uint64_t seed = 1;  ///< same seed, same path (std::mt19937_64)
};

/// A path start_q → q_goal (both included) whose straight joint-space segments keep the
/// obstacle clearance of the options and are free of self-collision and the floor by the self ε
/// (each sampled every 0.07 rad of its largest joint move); empty when none is found within
/// max_samples. Static obstacles only: obstacles that move are taken at their pose at time 0.
/// Throws std::invalid_argument for an obstacle the collision world refuses.
std::optional<std::vector<Eigen::VectorXd>> search_path(const Problem& problem,
                                                        const Eigen::VectorXd& q_goal,
                                                        const PathSearchOptions& options = {});

}  // namespace kinograph::planning

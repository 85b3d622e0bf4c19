#pragma once
// Initial trajectories for the batch planner: a smooth straight line (L) and a warm start from
// a previous plan (W).
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"

namespace kinograph::planning {

/// q, q̇, q̈ at states 0..steps (rows) for every joint (columns).
struct Trajectory {
  Eigen::MatrixXd q, qd, qdd;
};

/// The goal configuration to aim for: the joint goal itself, or for a pose goal a damped
/// least-squares inverse-kinematics solution started from start_q (clamped to the position
/// limits). Empty if the pose goal's frame is unknown.
std::optional<Eigen::VectorXd> goal_configuration(const Problem& problem);

/// Straight line in joint space from start to `q_goal` along a quintic time law (zero velocity
/// and acceleration at the goal, the start velocity at the start), so q, q̇, q̈ are consistent.
Trajectory straight_line(const Problem& problem, const Eigen::VectorXd& q_goal);

/// Two smooth straight lines, start → q_via over the first half of the steps (ending at rest) and
/// q_via → q_goal over the rest: a detour for when the straight line passes through an obstacle.
Trajectory via_point(const Problem& problem, const Eigen::VectorXd& q_via,
                     const Eigen::VectorXd& q_goal);

/// Smooth straight lines through `waypoints` (the start first, q_goal last), each along the
/// quintic time law of straight_line and at rest at every inner waypoint, with `steps[i]`
/// intervals for segment i (the steps sum to the problem's). Throws std::invalid_argument when
/// the sizes do not match or a segment has no step.
Trajectory segment_trajectory(const Problem& problem, const std::vector<Eigen::VectorXd>& waypoints,
                              const std::vector<int>& steps);

/// segment_trajectory through a path, its steps shared in proportion to the time each segment
/// needs at the velocity limits (at least 2 each). Throws std::invalid_argument for fewer than two
/// waypoints or more segments than half the steps.
Trajectory path_trajectory(const Problem& problem, const std::vector<Eigen::VectorXd>& waypoints);

/// Options of detour_candidates.
struct DetourOptions {
  int candidates = 24;  ///< random via points drawn (seeded, so plans are repeatable)
  double spread = 1.2;  ///< rad: via = midpoint + uniform(±spread) per joint, within limits
  int samples = 16;     ///< configurations checked per path segment
  std::uint64_t seed = 1;
};

/// A via point for via_point() and the clearance (m) of its two-segment path, capped at the
/// problem's collision ε (a path clearer than that reads ε).
struct Detour {
  Eigen::VectorXd via;
  double clearance = 0;
};

/// Detours drawn around the midpoint of start and goal, best first: ranked by the clearance of
/// their two-segment joint-space path to the problem's obstacles (capped at the planner's ε, so
/// among clear paths the shorter wins). Only the `best` best (all when negative): the others'
/// checks stop as soon as they cannot be among them. Empty without obstacles.
std::vector<Detour> detour_candidates(const Problem& problem, const Eigen::VectorXd& q_goal,
                                      const DetourOptions& options = {}, int best = -1);

/// Smallest clearance (m) to the problem's obstacles along the joint-space segment a → b,
/// travelled over the whole horizon and sampled at `samples` + 1 configurations (+inf without
/// obstacles).
double segment_clearance(const Problem& problem, const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                         int samples);

/// A previous plan resampled (piecewise linearly in time) to the problem's steps; the start
/// state is replaced by the problem's. Throws std::invalid_argument if the plan's joint count
/// differs or it has fewer than two states.
Trajectory warm_start(const Problem& problem, const Plan& previous);

}  // namespace kinograph::planning

#pragma once
// Initial trajectories for the batch planner: a smooth straight line (L) and a warm start from
// a previous plan (W).
#include <Eigen/Core>
#include <optional>
#include <string>

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

/// A previous plan resampled (piecewise linearly in time) to the problem's steps; the start
/// state is replaced by the problem's. Throws std::invalid_argument if the plan's joint count
/// differs or it has fewer than two states.
Trajectory warm_start(const Problem& problem, const Plan& previous);

}  // namespace kinograph::planning

#pragma once
// Bringing a moving robot to rest: a stopping trajectory from the state it is commanded to be
// in, on the plans' own interpolant, checked by planning::validate before anyone uses it.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "kinograph/dynamics/model.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"

namespace kinograph::execution {

/// The trajectory from (q0, q̇0) whose acceleration is linear between the breakpoints
/// times[i] (s, ascending, times[0] = 0), where it takes accelerations[i]: knots at every
/// breakpoint and `knots_per_piece` − 1 evenly between, with q and q̇ integrated exactly (so it
/// *is* the interpolant of its knots, docs/interpolation.md) and τ = RNEA at each knot.
/// Throws std::invalid_argument for sizes that do not match, times that do not increase or
/// knots_per_piece < 1.
planning::Plan linear_acceleration_plan(const dynamics::Model& model, const Eigen::VectorXd& q0,
                                        const Eigen::VectorXd& qd0,
                                        const std::vector<double>& times,
                                        const std::vector<Eigen::VectorXd>& accelerations,
                                        int knots_per_piece);

/// A stopping trajectory and what validate said of it.
struct StoppingTrajectory {
  bool valid = false;
  std::string reason;  ///< why no duration tried validates (the longest one's failures)
  double duration_s = 0;
  planning::Plan plan;  ///< knot 0 is the state stopped from; the last knot is at rest
};

/// Shortest and longest stop tried (s); durations double from the first to the last.
inline constexpr double kShortestStopS = 0.1;
inline constexpr double kLongestStopS = 6.4;

/// Brings the robot from (q, q̇, q̈) to rest: q̈ goes linearly from q̈ to a_m in T/2 and from
/// a_m to 0 in T/2, a_m = −(2q̇ + q̈T/2)/T so that q̇(T) = 0 (position, velocity and
/// acceleration continuous where the stop begins and ends). The shortest T of kShortestStopS,
/// 2·kShortestStopS, … kLongestStopS whose plan validates for `world` (its robot, obstacles,
/// floor, self pairs and every q, q̇, q̈, τ limit; task constraints are not kept) is taken.
/// Not valid, with the reason, when none does.
StoppingTrajectory stopping_trajectory(const planning::Problem& world, const Eigen::VectorXd& q,
                                       const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd);

}  // namespace kinograph::execution

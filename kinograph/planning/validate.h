#pragma once
// Checks a plan against its problem independently of the solver: the physics (inverse dynamics,
// integration consistency), every limit, collision at and between steps, start, goal and task
// constraints. "Success" means a plan validates.
#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"

namespace kinograph::planning {

/// Thresholds of validate(). The collision check requires no penetration (clearance ≥
/// min_clearance); the planner's safety distance ε is its own margin, not the validator's.
struct ValidationThresholds {
  double dynamics = 1e-3;              ///< max |τ − RNEA(q,q̇,q̈)| (N·m)
  /// Gap between where an interval's interpolant arrives and the next knot: q (rad), q̇ (rad/s).
  double position_consistency = 1e-3;
  double velocity_consistency = 1e-2;
  double limit = 1e-3;                 ///< allowed excess over any q, q̇, q̈, τ limit
  double unactuated_torque = 1e-3;     ///< max |τ| on unactuated joints (N·m)
  double min_clearance = 0.0;          ///< m; negative allows that much penetration
  double goal = 1e-2;                  ///< goal error (rad; m and rad for pose goals)
  double start = 1e-6;                 ///< start state error (rad, rad/s)
  double final_velocity = 1e-2;        ///< |q̇_N|, |q̈_N| at the goal
  /// Interpolant states per interval that the collision walk passes through; between them it
  /// bounds how far the interpolant strays from the straight segment. Fewer: a looser bound
  /// near obstacles, never a missed collision.
  int collision_samples = 10;
  /// Points per interval (the knot and interval_samples − 1 between, and at least one per RK4
  /// node of the interpolant: limit_points) where limits and the unactuated torque are
  /// checked on the interpolant; above 1, also where an actuated joint's cubic turns near a
  /// q or q̇ limit. 1: at the knots only.
  int interval_samples = 10;
};

/// Validates `plan` for `problem`: fills every figure of Validation, lists each failed check
/// in failures, and sets valid. Malformed plans (wrong sizes, NaN) are invalid, never a crash.
/// With verdict_only, the collision walk stops at the first sample that breaks the clearance
/// (min_clearance is then that sample's figure, not the path's least), and the clearance is not
/// reported when another check has failed, so min_clearance may be left unset then. The
/// physics and the pieces of the collision walk run on the process's worker pool
/// (graph/worker_pool.h) when it is free; the result is the same either way.
Validation validate(const Problem& problem, const Plan& plan,
                    const ValidationThresholds& thresholds = {}, bool verdict_only = false);

}  // namespace kinograph::planning

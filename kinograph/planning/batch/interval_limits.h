#pragma once
// Constraint generation for the limits between the knots: which intervals of a plan need the
// planner's interior limit points (IntervalDynamicsFactor), judged on the plan's interpolant at
// exactly those points. Most intervals of a plan never come near a limit between its knots, and
// their limit rows would cost inverse dynamics at every evaluation for nothing.
#include <vector>

#include "kinograph/planning/factors/interval_factors.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"

namespace kinograph::planning {

/// Per interval of `plan`, which limits its interpolant, at the planner's interior limit
/// points (limit_points(objectives.limit_substeps, Δt) evenly spaced), comes within `margin`
/// of (IntervalLimitRows bits): limits the planner enforces there, tightened by
/// objectives.limit_epsilon: the effort of an actuated joint (kEffortLimitRows), q or q̇
/// (kMotionLimitRows); with unactuated joints, whose points run the dynamics anyway, both
/// kinds wherever either is near. `margin` is a fraction of the limit (of the position range
/// for q).
/// All zeros when the problem has no interior limit points. Throws as TrajectorySampler.
std::vector<char> intervals_near_limits(const Problem& problem, const Plan& plan, double margin);

}  // namespace kinograph::planning

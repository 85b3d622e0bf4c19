#pragma once
// Continuation in the limits: a problem too tight to solve from a straight line is solved first
// with its effort and velocity limits widened, then again and again from the last plan with
// them narrowed, down to the problem's own (the way an underactuated swing-up under a weak motor
// is found from one under a stronger one).
#include <vector>

#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"

namespace kinograph::planning {

class BatchPlanner;

/// The problem with every finite effort and velocity limit multiplied by `scale` (> 0); the
/// model is copied, the rest is unchanged.
Problem with_scaled_limits(const Problem& problem, double scale);

/// Plans `problem` with its limits scaled by each of `scales` in turn (the first stage from the
/// planner's own initializations, each later one warm-started from the plan before it, valid or
/// not), then the problem itself warm-started from the last stage. Returns the plan of the
/// problem itself, with the iterations and attempts of every stage in its stats.
Plan plan_with_continuation(const BatchPlanner& planner, const Problem& problem,
                            const std::vector<double>& scales);

}  // namespace kinograph::planning

#pragma once
// Grid refinement: a problem on a fine grid is solved first on a coarser grid that divides its
// steps, and the fine solve starts from the coarse plan's interpolant sampled at the fine knots.
// A straight line is a poor start on a fine grid (many more variables to move, each barely
// coupled to the objective); the coarse plan is already feasible on the same interpolant.
#include "kinograph/planning/formulation/initialization.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"

namespace kinograph::planning {

/// The coarse grid a refinement of `problem` solves first: problem.steps / f for the smallest
/// factor f ≥ 2 of the steps, provided its intervals are at most `max_interval` long (s); 0 when
/// there is none (a prime number of steps, longer intervals, or max_interval ≤ 0).
int coarser_grid(const Problem& problem, double max_interval);

/// The initial trajectory of `fine` from a plan of the same motion on a grid that divides it:
/// the coarse plan's interpolant (TrajectorySampler) at the fine knots but the last (the coarse
/// plan's last knot), with the fine problem's start state. Throws std::invalid_argument when the
/// coarse plan's intervals do not divide fine.steps or its joints differ.
Trajectory refined_start(const Problem& fine, const Plan& coarse);

}  // namespace kinograph::planning

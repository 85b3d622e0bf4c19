#pragma once
// Continuation in the effort limits: a problem whose actuated joints are too weak to solve from
// a straight line (an underactuated swing-up) is solved first with its effort limits scaled up,
// then with them narrowed stage by stage, each stage warm-started from the last valid plan.
#include <vector>

#include "kinograph/planning/problem.h"

namespace kinograph::planning {

/// Whether the batch planner falls back to the continuation for `problem`: it has an
/// unactuated joint and an actuated joint with a finite effort limit.
bool effort_continuation_applies(const Problem& problem);

/// The problem with the finite effort limit of every actuated joint multiplied by `scale`
/// (the model copied). Throws std::invalid_argument unless scale > 0.
Problem with_effort_scaled(const Problem& problem, double scale);

}  // namespace kinograph::planning

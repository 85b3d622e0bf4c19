#pragma once
// A violated constraint row of a planning graph in the user's terms: which joint, link or
// obstacle, at what time, by how much and against which limit, read from the row's factor and
// its role key (e.g. "joint 2 (elbow) torque 8.6 N·m exceeds its 8 N·m limit by 0.6 N·m at
// t = 5.5 s").
#include <string>

#include "kinograph/planning/problem.h"
#include "kinograph/planning/solver/augmented_lagrangian.h"

namespace kinograph::planning {

/// What the worst row of `worst` means for `problem` (the problem the graph was built for).
/// "all constraints hold" when the report names no row.
std::string describe_violation(const Problem& problem, const ConstraintReport& worst);

/// The reason of a solve that ended infeasible: the iteration counts and the worst row in the
/// user's terms.
std::string infeasible_reason(const Problem& problem, const OuterLoopResult& result);

}  // namespace kinograph::planning

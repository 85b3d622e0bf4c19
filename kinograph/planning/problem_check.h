#pragma once
// Checks a planning problem before any solve: sizes, finite numbers, limits, frames, and a
// start and joint goal clear of the obstacles, the floor and the robot's own links.
#include <string>

#include "kinograph/planning/problem.h"

namespace kinograph::planning {

/// Why the problem cannot be planned, in the user's terms (joint, frame, obstacle or link pair
/// and depth); empty when it can.
std::string check_problem(const Problem& problem);

}  // namespace kinograph::planning

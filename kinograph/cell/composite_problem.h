#pragma once
// The centralized problem of a cell: all its robots as one composite robot
// (dynamics::compose), one planning problem whose self-collision pairs include every pair of
// links of different robots, and its plan split back into one plan per robot.
#include <string>
#include <vector>

#include "kinograph/cell/cell.h"
#include "kinograph/dynamics/model_compose.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"

namespace kinograph::cell {

/// The cell as one problem: the composite robot (names "<robot>/<joint>"), the robots' starts
/// and joint goals side by side, the shared obstacles, floor and objectives, the robots' task
/// constraints on their prefixed frames. Self pairs: each robot's own non-adjacent pairs minus
/// its allowed ones, and every pair of bodies of different robots (the bases all sit on the
/// composite's fixed base, so a robot's first link against another robot's base link is the one
/// cross pair not checked; cells place bases far beyond a first link's reach).
struct CompositeProblem {
  planning::Problem problem;
  std::vector<dynamics::ComposedRange> ranges;  ///< robot i's joints, in the cell's order
  std::vector<std::string> obstacle_names;      ///< problem.obstacles[i]'s name
};

/// The centralized problem of `cell`, whose robots must all have joint goals (see
/// resolve_pose_goals). @throws std::invalid_argument naming the robot: a pose goal, a floor
/// different from the first robot's.
CompositeProblem composite_problem(const Cell& cell);

/// Replaces each pose goal of the cell by a joint goal: the last state of that robot's plan
/// alone (its own scene) by `planner`. @throws std::invalid_argument naming the robot and the
/// reason when that plan does not validate.
void resolve_pose_goals(Cell& cell, const planning::BatchPlanner& planner);

/// Robot `range`'s part of a composite plan: its columns of q, q̇, q̈, τ, the same times and
/// solve statistics; its validation is left empty (validate it in the robot's own scene).
planning::Plan robot_plan(const planning::Plan& composite, const dynamics::ComposedRange& range);

/// The composite plan of the robots' plans (same times; columns side by side): what the
/// centralized problem would have planned. @throws std::invalid_argument when their times or
/// sizes differ.
planning::Plan composite_plan(const std::vector<planning::Plan>& plans,
                              const std::vector<dynamics::ComposedRange>& ranges);

}  // namespace kinograph::cell

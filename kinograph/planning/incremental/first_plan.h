#pragma once
// How a first plan becomes the incremental planner's Bayes tree: the batch planner's final
// graph and multipliers carried over (factors shared, collision rows split per obstacle), or
// the planning graph in incremental form solved by the outer loop itself.
#include <memory>
#include <string>

#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/incremental/incremental_tree.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"

namespace kinograph::planning {

/// μ of the tree built from a batch plan that ended at `batch_penalty`: a tenth of it, clamped
/// to [floor, kMaxCarriedPenalty]; when the plan is valid, at least its largest equality force
/// ten times over (up to `cap`), since a change moves the rows by a part of the forces over μ.
double carried_penalty(double batch_penalty, double largest_force, bool valid, double floor,
                       double cap);

/// The tree of a batch solution (condensed or DFG) without a second solve: each constraint's
/// forces λ + μc kept at the carried μ, the start and a joint goal turned into anchor factors
/// (the goal's multipliers from the Lagrangian's stationarity), collision factors per obstacle.
/// Null when the solution cannot be carried (no graph, repeated obstacle ids, a failed
/// elimination). `valid`: the batch plan validated (its multipliers are a solution's forces).
std::unique_ptr<IncrementalTree> carry_batch_solution(const Problem& problem,
                                                      BatchSolution& solution, bool valid,
                                                      const BatchPlannerOptions& batch,
                                                      const graph::ISAM2Options& isam2);

/// The planning graph of `problem` in incremental form, initialized to `init` and solved by the
/// augmented-Lagrangian outer loop with the start and joint goal fixed, then turned into a tree
/// at the result. The plan (validated) comes back through `plan`; the tree is null when the
/// problem cannot be built.
std::unique_ptr<IncrementalTree> solve_incremental_graph(const Problem& problem,
                                                         const Trajectory& init,
                                                         const std::string& method,
                                                         const BatchPlannerOptions& batch,
                                                         const graph::ISAM2Options& isam2,
                                                         Plan& plan);

}  // namespace kinograph::planning

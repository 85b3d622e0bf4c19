#pragma once
// DFGP batch planning: the problem's factor graph solved by Levenberg–Marquardt inside an
// augmented-Lagrangian outer loop, then validated independently.
#include "kinograph/planning/augmented_lagrangian.h"
#include "kinograph/planning/dfg_builder.h"
#include "kinograph/planning/graph_builder.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"
#include "kinograph/planning/validate.h"

namespace kinograph::planning {

/// How the equations of motion enter the graph. Both pose the same problem (same torque rows)
/// and give the same plans; the condensed form has far fewer variables and is the faster.
enum class Formulation {
  kCondensed,           ///< τ = RNEA(q, q̇, q̈) eliminated into one factor per step
  kDynamicFactorGraph,  ///< the paper's DFG: V, V̇, F, τ variables, 4 equations per joint and step
};

/// "condensed" or "dfg" (the scene file's planner.formulation names).
std::string to_string(Formulation f);

/// Options of BatchPlanner, defaults tuned on the shipped scenes.
struct BatchPlannerOptions {
  Formulation formulation = Formulation::kCondensed;
  /// Keys, scale and external wrenches of the DFG formulation (unused when condensed).
  DfgOptions dfg;
  GraphOptions graph;
  AugmentedLagrangianOptions augmented_lagrangian;
  /// Stop when every constraint row's scaled violation |z/s| is below this.
  double constraint_tolerance = 1e-4;
  int max_outer_iterations = 15;          ///< augmented-Lagrangian updates
  int max_inner_iterations = 15;          ///< LM linearizations per outer iteration
  int max_total_iterations = 400;         ///< LM linearizations over the whole plan
  double inner_tolerance_initial = 1e-2;  ///< LM relative decrease in the first outer iteration
  double inner_tolerance_final = 1e-7;    ///< ... tightened by 10× per outer iteration to this
  ValidationThresholds validation;
};

/// Plans a trajectory for a Problem from a straight-line (L) or warm-start (W) initialization.
class BatchPlanner {
 public:
  explicit BatchPlanner(BatchPlannerOptions options = {});

  /// Never throws for problems that are merely impossible: they come back with status
  /// "invalid_problem" (bad input: sizes, NaN, goal outside limits, start in collision) or
  /// "infeasible" (constraints still violated at the iteration limit) and a reason. Always
  /// runs validate().
  Plan plan(const Problem& problem, const Plan* warm_start = nullptr) const;

  const BatchPlannerOptions& options() const { return options_; }

 private:
  BatchPlannerOptions options_;
};

/// Reasons a problem cannot be planned before any solve (empty when it can).
std::string check_problem(const Problem& problem);

}  // namespace kinograph::planning

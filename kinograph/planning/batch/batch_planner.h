#pragma once
// DFGP batch planning: the problem's factor graph solved by Levenberg–Marquardt inside an
// augmented-Lagrangian outer loop, then validated independently.
#include "kinograph/planning/solver/augmented_lagrangian.h"
#include "kinograph/planning/formulation/dfg_builder.h"
#include "kinograph/planning/formulation/planning_graph.h"
#include "kinograph/planning/formulation/initialization.h"
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
  /// Keys, scale and external wrenches of the DFG formulation (unused when condensed). The
  /// equation rows keep scale 1: smaller scales weight them so heavily that LM stalls on the
  /// objective (plans then differ from the condensed ones).
  DfgOptions dfg;
  /// constraint_tolerance of the DFG formulation: its equation rows' errors accumulate along the
  /// chain into τ (about 20× on the iiwa), which must stay within the validator's 1e-3 N·m.
  double dfg_constraint_tolerance = 2e-5;
  /// inner_tolerance_final of the DFG formulation: at the condensed default the inner solves
  /// stop after one LM step and the multipliers stall above dfg_constraint_tolerance.
  double dfg_inner_tolerance_final = 1e-7;
  GraphOptions graph;
  AugmentedLagrangianOptions augmented_lagrangian;
  /// Stop when every constraint row's scaled violation |z/s| is below this. With the default
  /// scales that is 1e-4 rad (rad/s, rad/s²) on limits, 1e-3 N·m on torques, 3e-5 m on
  /// collision: within the validator's thresholds, which a converged plan therefore meets.
  double constraint_tolerance = 1e-3;
  int max_outer_iterations = 15;          ///< augmented-Lagrangian updates
  int max_inner_iterations = 15;          ///< LM linearizations per outer iteration
  int max_total_iterations = 400;         ///< LM linearizations over the whole plan
  double inner_tolerance_initial = 1e-2;  ///< LM relative decrease in the first outer iteration
  /// ... tightened by 10× per outer iteration to this. Loose: plans are feasible long before
  /// their objective is polished (1e-7 took 142 instead of 91 LM iterations on the Acrobot
  /// swing-up for a soft cost 3 % lower: 6181 instead of 6350).
  double inner_tolerance_final = 1e-3;
  ValidationThresholds validation;
  /// When the straight-line (L) plan of a problem with obstacles does not validate, up to this
  /// many more attempts start from detours (via_point() through detour_candidates()); the plan
  /// returned is the first that validates (else the one with the smallest constraint violation),
  /// and its stats count every attempt; each attempt has its own iteration limits. 0 = never.
  int max_restarts = 4;
  /// Start from the best detour instead when the straight line collides and the detour's path
  /// does not (the straight line is then the first restart).
  bool detour_first = true;
  DetourOptions detour;
};

/// Where the solve of a plan ended: its graph (whose constraint factors hold the final
/// multipliers), values and penalty μ. The incremental planner starts its Bayes tree from this
/// instead of solving the problem again.
struct BatchSolution {
  PlanningGraph graph;
  double penalty = 0;     ///< μ of the augmented Lagrangian at the end
  bool condensed = true;  ///< false: the DFG formulation's graph (other variables and factors)
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
  /// The same plan, and (when `solution` is non-null) the final state of the attempt it came
  /// from; numerically identical to plan().
  Plan plan(const Problem& problem, const Plan* warm_start, BatchSolution* solution) const;

  const BatchPlannerOptions& options() const { return options_; }

 private:
  /// One augmented-Lagrangian solve from `init`, validated; its final state goes to `solution`
  /// when that is non-null.
  Plan solve(const Problem& problem, const Trajectory& init, const std::string& method,
             BatchSolution* solution = nullptr) const;

  BatchPlannerOptions options_;
};

/// Reasons a problem cannot be planned before any solve (empty when it can).
std::string check_problem(const Problem& problem);

}  // namespace kinograph::planning

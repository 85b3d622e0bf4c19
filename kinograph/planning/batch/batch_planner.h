#pragma once
// DFGP batch planning: the problem's factor graph solved by Levenberg–Marquardt inside an
// augmented-Lagrangian outer loop, then validated independently.
#include <optional>
#include <vector>

#include "kinograph/planning/batch/effort_continuation.h"
#include "kinograph/planning/batch/path_search.h"
#include "kinograph/planning/formulation/dfg_builder.h"
#include "kinograph/planning/formulation/initialization.h"
#include "kinograph/planning/formulation/planning_graph.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"
#include "kinograph/planning/problem_check.h"
#include "kinograph/planning/solver/augmented_lagrangian.h"
#include "kinograph/planning/solver/constraint_state.h"
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

/// Options of BatchPlanner; the defaults plan the shipped scenes.
struct BatchPlannerOptions {
  Formulation formulation = Formulation::kCondensed;
  /// Keys, scale and external wrenches of the DFG formulation (unused when condensed). Its
  /// equation rows keep scale 1: smaller ones outweigh the objective and LM stalls on it.
  DfgOptions dfg;
  /// constraint_tolerance of the DFG formulation: its equation rows' errors accumulate along the
  /// chain into τ, which must stay within the validator's torque threshold.
  double dfg_constraint_tolerance = 2e-5;
  /// inner_tolerance_final of the DFG formulation: looser inner solves stop after one LM step
  /// and its multipliers stall above dfg_constraint_tolerance.
  double dfg_inner_tolerance_final = 1e-7;
  GraphOptions graph;
  AugmentedLagrangianOptions augmented_lagrangian;
  /// Tolerances and iteration limits of the outer loop. With the default scales its constraint
  /// tolerance 1e-3 is 1e-4 rad (rad/s, rad/s²) on limits, 1e-3 N·m on torques and 3e-5 m on
  /// collision: within the validator's thresholds, which a converged plan therefore meets. The
  /// final inner tolerance is loose: plans are feasible long before their objective is polished.
  OuterLoopOptions outer_loop;
  ValidationThresholds validation;
  /// When the straight-line (L) plan of a problem with obstacles does not validate, up to this
  /// many more attempts start from detours (via_point() through detour_candidates()) and, with
  /// path_search on, one from a searched path (skipped when none is found); the plan
  /// returned is the first that validates (else the one with the smallest constraint violation),
  /// and its stats count every attempt; each attempt has its own iteration limits. 0 = never.
  int max_restarts = 4;
  /// Start from the best detour instead when the straight line collides and the detour's path
  /// does not (the straight line is then the first restart).
  bool detour_first = true;
  DetourOptions detour;
  /// One restart starts from a collision-free path (search_path, timed by path_trajectory): when
  /// the straight line collides, first (second after the best detour when that detour's path is
  /// clear); else right after a failed first attempt. max_samples = 0 switches it off.
  PathSearchOptions path_search;
  /// An attempt whose knot-only solve ends infeasible (its violation stalled at the largest
  /// penalty, or its iterations ran out) with a worst scaled violation above this ends there,
  /// and the next initialization starts at once: the rows between the knots only add
  /// constraints to a solve already this far from feasible. Scaled as
  /// OuterLoopOptions::constraint_tolerance; the default, a collision row 6 cm inside its safety
  /// distance at the default scale, lies far above where attempts that still end valid stall.
  /// 0 = every attempt goes on to the rows between the knots.
  double abandon_violation = 2;
  /// When no attempt validates and the robot has an unactuated joint and a finite effort limit
  /// (effort_continuation_applies), one more attempt by continuation in the effort limits: the
  /// problem with every actuated joint's limit multiplied by each of these factors in turn (the
  /// first from the straight line, each later one and finally the problem itself warm-started
  /// from the last stage that validated). Dimensionless, > 0; empty = off.
  std::vector<double> effort_continuation{2, 1.5, 1.25, 1.125, 1.0625};
  /// RK4 step (s) of a warm-up solve between the knot-only solve and the one on the
  /// interpolant, for robots with an unactuated joint: the same rows (shooting defects, limit
  /// points) integrated in steps this long, which cost a fraction of the interpolant's
  /// kMaxIntegrationStep and leave the final solve on the interpolant a short projection, or
  /// none when the warm-up already holds the interpolant's rows. Used only when it takes
  /// fewer steps per interval than the interpolant; 0 = off.
  double warmup_integration_step = 0.05;
  /// Grid refinement (grid_refinement.h): a problem whose steps have a coarser grid with
  /// intervals at most this long (s) is first planned on that grid, by this planner (so
  /// recursively, down to intervals of about this length), and its first attempt starts from the
  /// coarse plan's interpolant at its knots, on the interpolant from its first solve; the other
  /// initializations follow if that does not validate. The plan's stats count the coarse
  /// plans' iterations and attempts. The shipped scenes' 0.1 s grids are not refined; an Acrobot
  /// swing-up over 10 s in 400 steps is planned from 100 and 200 steps. 0 = off.
  double refine_max_interval = 0.1;
};

/// Where the solve of a plan ended: its graph, values and the constraint state (final
/// multipliers and μ). The incremental planner starts its Bayes tree from this instead of
/// solving the problem again.
struct BatchSolution {
  PlanningGraph graph;
  ConstraintState constraints;
};

/// The plan at the end of an outer loop on `pg` (plan_from_values), with its stats from `r`
/// and `method`, its soft cost, and its validation.
Plan solved_plan(const Problem& problem, const PlanningGraph& pg, const OuterLoopResult& r,
                 const std::string& method, const BatchPlannerOptions& options);

/// The outer loop's options for the configured formulation (the DFG's tighter tolerances).
OuterLoopOptions outer_loop_options(const BatchPlannerOptions& options);

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
  /// when that is non-null. With `from_interpolant`, `init` is already feasible on the interpolant
  /// (a coarse plan's): the knot-only and warm-up solves are skipped, and the first solve is a
  /// projection onto the rows on the interpolant at the largest penalty.
  Plan solve(const Problem& problem, const Trajectory& init, const std::string& method,
             BatchSolution* solution = nullptr, bool from_interpolant = false) const;
  /// The continuation attempt (options().effort_continuation), its stats summed over every
  /// stage; the final solve's state goes to `solution` when that is non-null.
  Plan solve_by_effort_continuation(const Problem& problem, const Eigen::VectorXd& q_goal,
                                    const std::string& method, BatchSolution* solution) const;

  /// The grid-refinement attempt: the problem planned on `coarse_steps`, then solved from that
  /// plan's interpolant; empty when the coarse plan does not validate. The coarse plan's own
  /// iterations and attempts are added to `coarse_stats`.
  std::optional<Plan> solve_refined(const Problem& problem, int coarse_steps,
                                    const std::string& method, SolveStats& coarse_stats,
                                    BatchSolution* solution) const;

  BatchPlannerOptions options_;
};

}  // namespace kinograph::planning

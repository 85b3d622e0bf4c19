#pragma once
// The augmented-Lagrangian method over a planning graph's constraint factors: the penalty
// schedule, the multiplier updates, and the outer loop around Levenberg–Marquardt inner solves
// that both planners run (the batch planner for every plan, the incremental planner when it
// has to solve its own graph). Multipliers live in a ConstraintState beside the graph, so
// changing them never changes the graph's structure and the LM solves keep their symbolic
// analysis.
#include <string>
#include <vector>

#include "kinograph/graph/factor_graph.h"
#include "kinograph/graph/values.h"
#include "kinograph/planning/formulation/planning_graph.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/solver/constraint_state.h"

namespace kinograph::planning {

/// Penalty schedule of AugmentedLagrangian.
struct AugmentedLagrangianOptions {
  double initial_penalty = 100;     ///< μ₀
  double penalty_growth = 10;       ///< μ ← growth·μ when the violation did not shrink enough
  double max_penalty = 1e7;         ///< μ never exceeds this
  double required_decrease = 0.25;  ///< violation must fall below this fraction of the last one
};

/// The worst constraint row of a graph, for reports.
struct ConstraintReport {
  double scaled_violation = 0;  ///< max |c| (violation / scale)
  double violation = 0;         ///< the same row's violation in its own units
  std::string where;            ///< factor name and first key, e.g. "DynamicsStepFactor q(0,12)"
  /// The entry and row of that worst violation (null / −1 when every row holds), and the row's
  /// raw value, from which describe_violation says what it means to the user.
  const FactorEntry* entry = nullptr;
  int row = -1;
  double value = 0;
};

/// The worst constraint row over `constraints` at `values` (one evaluation of each, on the
/// process's workers when they are many): the first of the worst in their order.
ConstraintReport worst_constraint(const std::vector<const FactorEntry*>& constraints,
                                  const graph::Values& values);

/// The schedule over a set of constraint entries whose multipliers live in `state`.
class AugmentedLagrangian {
 public:
  /// Binds every entry to `state` and sets μ₀. The entries and the state must outlive this.
  AugmentedLagrangian(std::vector<const FactorEntry*> constraints, ConstraintState& state,
                      AugmentedLagrangianOptions options = {});

  double penalty() const { return state_.penalty(); }
  /// Whether μ has reached AugmentedLagrangianOptions::max_penalty.
  bool at_max_penalty() const { return state_.penalty() >= options_.max_penalty; }
  /// Multiplier updates in a row, at the largest penalty, whose worst violation did not fall
  /// a tenth below the smallest one seen at that penalty.
  int stalled_updates() const { return stalled_updates_; }
  /// The worst scaled violation at `values` and where it is.
  ConstraintReport report(const graph::Values& values) const;
  /// After an inner solve: λ ← λ + μc on every factor, then μ grows unless the worst scaled
  /// violation fell below required_decrease × the previous one. Returns that violation.
  double update(const graph::Values& values);
  /// report() and update() from one evaluation of each constraint: the worst row at `values`;
  /// the multipliers and μ are updated unless its scaled violation is at most `tolerance`
  /// (then they are left exactly as they were). A negative tolerance always updates.
  ConstraintReport update_unless_within(const graph::Values& values, double tolerance);

 private:
  std::vector<const FactorEntry*> constraints_;
  std::vector<Multipliers*> multipliers_;  // each constraint's record in state_, same order
  ConstraintState& state_;
  AugmentedLagrangianOptions options_;
  double last_violation_ = -1;
  int stalled_updates_ = 0;
  double best_at_max_ = -1;  // smallest worst violation after an update at the largest μ
  std::vector<Multipliers> saved_;  // update_unless_within's copy, reused
  std::vector<ConstrainedFactor::Violation> violations_;  // per constraint, reused
};

/// Limits and tolerances of the outer loop.
struct OuterLoopOptions {
  /// Stop when every constraint row's scaled violation |z/s| is below this.
  double constraint_tolerance = 1e-3;
  int max_outer_iterations = 15;          ///< augmented-Lagrangian updates
  int max_inner_iterations = 15;          ///< LM linearizations per outer iteration
  int max_total_iterations = 400;         ///< LM linearizations over the whole solve
  double inner_tolerance_initial = 1e-2;  ///< LM relative decrease in the first outer iteration
  /// ... tightened by 10× per outer iteration down to this (feasible plans stop here).
  double inner_tolerance_final = 1e-3;
  /// In a solve that starts at the largest μ (the batch planner's re-solves after it adds
  /// between-knot rows), each inner solve after the first starts LM's damping at this multiple
  /// of the last one's final λ (at most LM's λ₀): the curvature is nearly the same, and
  /// restarting at λ₀ spends iterations undoing damping, or stops early on a heavily damped
  /// step that barely moves. Not at smaller μ, where LM would run on along the objective: lower
  /// objectives, but slower first plans and slower replans from them. 0 always starts at λ₀.
  double damping_carry = 10;
  /// Gives up after this many stalled multiplier updates (AugmentedLagrangian::
  /// stalled_updates): at the largest penalty a violation that no longer shrinks is a local
  /// infeasibility the growing multipliers do not cure. 0 runs to max_outer_iterations.
  int max_stalled_updates = 3;
};

/// What the outer loop ended with.
struct OuterLoopResult {
  PlanStatus status = PlanStatus::kInfeasible;  ///< kConverged, kInfeasible or kNonFinite
  std::string reason;  ///< why, when not converged
  int iterations = 0;  ///< LM linearizations
  int outer_iterations = 0;
  int linear_solves = 0;
  ConstraintReport worst;  ///< at the end
  SolveTimes times;        ///< the LM and multiplier parts (validation_s stays 0)
};

/// Runs LM on `graph` from `values` inside the augmented-Lagrangian outer loop until the
/// constraints hold at the final inner tolerance or a limit is reached; `values` ends at the
/// last iterate. `name` labels the debug log lines.
OuterLoopResult solve_outer_loop(const graph::FactorGraph& graph, graph::Values& values,
                                 AugmentedLagrangian& al, const OuterLoopOptions& options,
                                 const std::string& name);

}  // namespace kinograph::planning

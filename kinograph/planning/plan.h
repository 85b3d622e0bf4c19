#pragma once
// A planned trajectory: states, accelerations and torques at every step, with how it was
// solved and whether it validates.
#include <Eigen/Core>
#include <iosfwd>
#include <limits>
#include <string>
#include <vector>

namespace kinograph::planning {

/// How the solve of a plan ended (whether the plan is a success is validation's verdict).
enum class PlanStatus {
  kConverged,       ///< the constraints hold at the solver's final tolerance
  kInfeasible,      ///< constraints still violated at the iteration limit
  kNonFinite,       ///< a factor returned NaN or inf
  kSingular,        ///< a linear system was singular
  kMaxUpdates,      ///< incremental: the update limit was reached
  kMaxRounds,       ///< incremental: the multiplier-round limit was reached
  kInvalidProblem,  ///< refused before any solve; the reason says why
  kNoPlan,          ///< a replan asked of a planner without a plan
  kFailed,          ///< no solve result (e.g. a failure read back from a message)
};

/// "converged", "infeasible", "non_finite", "singular", "max_updates", "max_rounds",
/// "invalid_problem", "no_plan", "failed" (the names plan files use).
std::string to_string(PlanStatus status);
/// The status of a name of to_string(); throws std::invalid_argument for any other.
PlanStatus plan_status_from_string(const std::string& name);
std::ostream& operator<<(std::ostream& os, PlanStatus status);

/// Where the wall time of a plan's batch solves went, in seconds summed over every attempt. The
/// rest of SolveStats::solve_time_s is the problem check (the first collision world of a mesh
/// robot reads its hulls there), bookkeeping, the set-up of effort continuation and, for an
/// incremental update, all of its Bayes-tree work and checks. A part not run stays 0.
struct SolveTimes {
  /// Initial trajectories: the straight line or warm start, detours, the path search.
  double initialization_s = 0;
  double graph_building_s = 0;    ///< building the planning graphs
  double linearization_s = 0;     ///< residuals, Jacobians and normal equations of LM solves
  double factorization_s = 0;     ///< symbolic analysis and numeric Cholesky of LM solves
  double triangular_solve_s = 0;  ///< triangular solves of LM solves
  double multipliers_s = 0;       ///< augmented-Lagrangian multiplier updates
  /// Checks of the interpolant between the knots that choose the rows of the next solve.
  double between_knot_checks_s = 0;
  double validation_s = 0;  ///< validate() on the plan each batch solve ended with

  SolveTimes& operator+=(const SolveTimes& other);
  /// The sum of the parts.
  double total_s() const;
};

/// How a plan was solved.
struct SolveStats {
  std::string method;        ///< "batch-L", "batch-W", "incremental"
  PlanStatus status = PlanStatus::kConverged;
  std::string reason;        ///< one line explaining a non-converged status
  int iterations = 0;        ///< LM linearizations over all inner solves
  int outer_iterations = 0;  ///< augmented-Lagrangian outer iterations
  int linear_solves = 0;     ///< sparse factorizations + solves
  int attempts = 1;          ///< solves from different initializations (restarts + 1)
  double solve_time_s = 0;   ///< wall time of the whole plan() call
  double cost = 0;           ///< final soft cost ½Σ‖r‖² (without constraint terms)
  double max_constraint_violation = 0;  ///< largest must-hold residual at the end
  SolveTimes times;                     ///< where solve_time_s went
};

/// Adds the work of `from` (iterations, outer iterations, linear solves and times) to `into`.
void add_work(SolveStats& into, const SolveStats& from);

/// The checks of validate(), figure by figure; failures lists one line per failed check.
struct Validation {
  bool valid = false;
  std::vector<std::string> failures;
  double max_dynamics_residual = 0;     ///< max |τ − RNEA(q, q̇, q̈)| (N·m)
  /// max |q_{k+1} − q(t_{k+1}⁻)| (rad): the gap between where the interpolant of interval k
  /// arrives and knot k+1 (collocation of actuated joints, shooting defect of unactuated ones)
  double max_position_consistency = 0;
  double max_velocity_consistency = 0;  ///< the same for q̇ (rad/s)
  double max_q_violation = 0;    ///< how far q leaves [lower, upper], at and between the knots
  double max_qd_violation = 0;   ///< how far |q̇| exceeds the velocity limit, at and between
  double max_qdd_violation = 0;  ///< how far |q̈| exceeds a finite acceleration limit, same
  double max_tau_violation = 0;  ///< how far the knots' |τ| exceeds the effort limit (N·m)
  /// How far |τ| on the interpolant between the knots exceeds the effort limit (N·m).
  double max_tau_violation_between = 0;
  /// max |τ| on unactuated joints on the interpolant between the knots (N·m).
  double max_unactuated_torque_between = 0;
  double min_clearance = std::numeric_limits<double>::infinity();  ///< m, over steps and between
  double goal_error = 0;             ///< joint goal: max |q_N − q_goal|; pose goal: max(m, rad)
  double max_task_error = 0;         ///< worst task-constraint error (rad or m)
  double max_unactuated_torque = 0;  ///< max |τ| on unactuated joints at the knots (N·m)
  double start_error = 0;            ///< max |q_0 − start_q|, |q̇_0 − start_qd|
  double final_velocity = 0;         ///< max |q̇_N|, |q̈_N| (the goal is at rest)
};

/// A trajectory: rows are states 0..steps, columns joints.
struct Plan {
  std::vector<double> t;
  Eigen::MatrixXd q, qd, qdd, tau;
  SolveStats stats;
  Validation validation;

  /// A plan succeeds only if it validates.
  bool success() const { return validation.valid; }
};

/// A plan without trajectory that failed before or in its solve: `status` and `reason` in its
/// stats and its validation's one failure.
Plan failed_plan(const std::string& method, PlanStatus status, const std::string& reason);

/// The motion of a robot that went on `knots` knots along `plan`, at the same knot times: its
/// knots from `knots` on, then its last position at rest (τ held). Stats and validation are
/// left empty. Throws std::invalid_argument unless 0 <= knots < the number of knots.
Plan gone_on(const Plan& plan, int knots);

}  // namespace kinograph::planning

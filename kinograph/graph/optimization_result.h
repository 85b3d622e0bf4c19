#pragma once
// What a batch solve reports: a status with a reason, and per-iteration statistics.
#include <string>
#include <vector>

namespace kinograph::graph {

/// Outcome of a solve. Only kConverged means a tolerance was met.
enum class SolverStatus {
  kConverged,      ///< relative or absolute error tolerance met (or step too small to matter)
  kMaxIterations,  ///< iteration limit reached first
  kNoDecrease,     ///< no step decreased the error (LM: λ reached its maximum)
  kSingular,       ///< the normal equations are singular or indefinite
  kNonFinite,      ///< a residual or Jacobian held NaN/Inf (reason names the factor)
};

/// "converged", "max_iterations", "no_decrease", "singular", "non_finite".
std::string to_string(SolverStatus status);

/// One trial step: each linearization starts an iteration; LM may try several λ in it.
struct IterationStats {
  int iteration = 0;       ///< index of the linearization this trial belongs to
  double error = 0;        ///< cost after the trial if accepted, else the trial's cost
  double lambda = 0;       ///< damping used (0 for Gauss–Newton)
  double step_norm = 0;    ///< ‖δ‖₂
  bool accepted = false;   ///< whether the step was kept
  double linearize_s = 0;  ///< seconds assembling H, g (0 when reused from the previous trial)
  double factorize_s = 0;  ///< seconds in numeric Cholesky
  double solve_s = 0;      ///< seconds in triangular solves
  double evaluate_s = 0;   ///< seconds evaluating the cost at the trial point
};

/// Result of a batch solve; the Values passed in hold the final estimate.
struct OptimizationResult {
  SolverStatus status = SolverStatus::kConverged;
  std::string reason;                   ///< one line, names the factor or variable when relevant
  int iterations = 0;                   ///< linearizations performed
  int trials = 0;                       ///< linear solves performed (≥ iterations for LM)
  double initial_error = 0;             ///< ½Σ‖r‖² at the start
  double final_error = 0;               ///< ½Σ‖r‖² at the returned values
  double lambda = 0;                    ///< final damping (LM)
  std::vector<IterationStats> history;  ///< one entry per trial (if options ask for it)
  double symbolic_s = 0;   ///< seconds building structure and symbolic analysis (0 if cached)
  double linearize_s = 0;  ///< totals over the solve
  double factorize_s = 0;
  double solve_s = 0;
  double evaluate_s = 0;
  double total_s = 0;

  bool converged() const { return status == SolverStatus::kConverged; }
};

}  // namespace kinograph::graph

#pragma once
// Batch Levenberg–Marquardt on the sparse normal equations with CHOLMOD: the DFGP solver.
#include <memory>
#include <string>

#include "kinograph/graph/factor_graph.h"
#include "kinograph/graph/optimization_result.h"
#include "kinograph/graph/ordering.h"
#include "kinograph/graph/sparse_cholesky.h"
#include "kinograph/graph/values.h"

namespace kinograph::graph {

class NormalEquations;

/// How LM damps H: (H + λD) δ = −g.
enum class Damping {
  kDiagonal,  ///< D = diag(H) clamped to [min_diagonal, max_diagonal] (Marquardt; scale-free)
  kIdentity,  ///< D = I (Levenberg; GTSAM's default)
};

/// Options of LevenbergMarquardt; defaults as the paper (λ₀ = 0.01, 200 iterations, relative
/// decrease 1e-5).
struct LevenbergMarquardtOptions {
  /// λ₀: damping of the first trial (the factor on D).
  double lambda_initial = 0.01;
  /// Give up (no decrease, or singular) once λ exceeds this after a rejected trial.
  double lambda_max = 1e12;
  /// Floor of λ after accepted steps.
  double lambda_min = 1e-15;
  /// The matrix D that λ scales in (H + λD) δ = −g.
  Damping damping = Damping::kDiagonal;
  /// Lower clamp of diag(H) in D for kDiagonal (keeps H + λD definite on empty columns).
  double min_diagonal = 1e-6;
  /// Upper clamp of diag(H) in D for kDiagonal.
  double max_diagonal = 1e32;
  /// Maximum number of linearizations per solve (each starts an iteration of one or more trials).
  int max_iterations = 200;
  /// Converged when an accepted step lowers the cost by less than this fraction of it.
  double relative_error_tol = 1e-5;
  /// Converged when the cost ½Σ‖r‖² is at or below this (same units as the cost).
  double absolute_error_tol = 0;
  /// Converged when the step ‖δ‖₂ ≤ step_tol·(‖x‖₂ + step_tol) (relative, dimensionless).
  double step_tol = 1e-14;
  /// Elimination order of the variables, which sets the fill of the Cholesky factor.
  OrderingMethod ordering = OrderingMethod::kAmd;
  /// How H + λD is factorized (kAuto: the envelope in natural order when it adds little fill,
  /// as for a trajectory, else CHOLMOD's choice in `ordering`).
  Factorization factorization = Factorization::kAuto;
  /// Threads that may evaluate the factors (the caller's and up to threads − 1 of the
  /// process's pool, as many as the machine has cores for); a graph is shared out only when it
  /// has enough factors and timing shows it pays (ShareOutChoice). The solve is the same to the
  /// bit for any value; 1 keeps it on the caller's thread, e.g. beside other busy processes.
  int threads = 2;
  /// Take Jacobians at every trial point, so an accepted step is not linearized a second time.
  bool linearize_at_evaluation = true;
  /// Fill OptimizationResult::history, one entry per trial.
  bool record_history = true;
  /// Log an spdlog debug line per trial and one at the end.
  bool log_iterations = false;
};

/// Levenberg–Marquardt with Nielsen's λ update (λ shrinks by up to 3× after good steps, grows
/// by 2, 4, 8… after rejected ones). Structure (ordering, pattern of H, CHOLMOD symbolic
/// analysis) is cached across calls and rebuilt only when the graph's structure_id() or the
/// Values' layout_id() changes, so re-solving after changing targets or noise models is cheap.
class LevenbergMarquardt {
 public:
  explicit LevenbergMarquardt(LevenbergMarquardtOptions options = {});
  ~LevenbergMarquardt();
  LevenbergMarquardt(LevenbergMarquardt&&) noexcept;
  LevenbergMarquardt& operator=(LevenbergMarquardt&&) noexcept;

  /// Minimizes the graph's cost starting from `values`, which hold the result on return (the
  /// best point found, also on failure). Throws only for inconsistent input (missing keys, wrong
  /// dimensions); numerical trouble comes back as a status.
  OptimizationResult optimize(const FactorGraph& graph, Values& values);

  const LevenbergMarquardtOptions& options() const { return options_; }
  /// Changing ordering, factorization or threads forces a rebuild on the next optimize().
  void set_options(const LevenbergMarquardtOptions& options);
  /// The cached CHOLMOD factorization (null before the first solve or when the envelope
  /// factorization is used), e.g. to see which form kAuto chose.
  const SparseCholesky* cholesky() const;
  /// Whether the last solve factorized H within its envelope (EnvelopeCholesky).
  bool uses_envelope() const;

 private:
  struct Solve;  // one optimize() call's state
  struct Trial;  // what one trial step did

  // The steps of optimize(); those returning bool return true once the solve has ended (status
  // and reason set by finish()).
  void prepare(const FactorGraph& graph, const Values& values, Solve& s);
  void build_structure(const FactorGraph& graph, const Values& values);
  bool start(const FactorGraph& graph, const Values& values, Solve& s);
  void update_damping(Solve& s) const;
  bool run_trial(const FactorGraph& graph, Values& values, Solve& s);
  Trial try_step(const FactorGraph& graph, Values& values, Solve& s, IterationStats& stats);
  bool factorize_damped(Solve& s, IterationStats& stats);
  void evaluate_step(const FactorGraph& graph, Values& values, Solve& s, IterationStats& stats,
                     Trial& trial);
  void accept_step(Solve& s, double predicted, double new_error, bool at_rounding,
                   Trial& trial) const;
  void record(Solve& s, const IterationStats& stats) const;
  bool next_iteration(const FactorGraph& graph, const Values& values, Solve& s, const Trial& trial);
  bool increase_lambda(const Values& values, Solve& s, bool factored) const;
  void finish(Solve& s, SolverStatus status, std::string reason) const;

  LevenbergMarquardtOptions options_;
  std::unique_ptr<NormalEquations> equations_;
  std::unique_ptr<NormalEquations> candidate_;  // linearized at the trial step
  std::unique_ptr<CholeskyFactor> cholesky_;  // SparseCholesky or EnvelopeCholesky
};

}  // namespace kinograph::graph

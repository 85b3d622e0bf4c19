#pragma once
// Batch Levenberg–Marquardt on the sparse normal equations with CHOLMOD: the DFGP solver.
#include <memory>

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
  double lambda_initial = 0.01;  ///< λ₀
  double lambda_max = 1e12;      ///< give up (no decrease / singular) when λ exceeds this
  double lambda_min = 1e-15;     ///< λ never drops below this
  Damping damping = Damping::kDiagonal;
  double min_diagonal = 1e-6;  ///< clamp of diag(H) for kDiagonal (keeps H + λD definite)
  double max_diagonal = 1e32;
  int max_iterations = 200;          ///< linearizations
  double relative_error_tol = 1e-5;  ///< converged when (e_old − e_new)/e_old < this after a step
  double absolute_error_tol = 0;     ///< converged when e ≤ this
  double step_tol = 1e-14;           ///< converged when ‖δ‖ ≤ step_tol·(‖x‖ + step_tol)
  OrderingMethod ordering = OrderingMethod::kAmd;
  Factorization factorization = Factorization::kAuto;
  /// Evaluate a trial step's error together with its Jacobians (into a second set of normal
  /// equations): an accepted step is then not evaluated again to linearize there. A rejected
  /// step wastes the Jacobians.
  bool linearize_at_evaluation = true;
  bool record_history = true;   ///< fill OptimizationResult::history
  bool log_iterations = false;  ///< spdlog debug line per trial
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
  /// Changing ordering or factorization forces a rebuild on the next optimize().
  void set_options(const LevenbergMarquardtOptions& options);
  /// The cached CHOLMOD factorization (null before the first solve), e.g. to see which form
  /// kAuto chose.
  const SparseCholesky* cholesky() const { return cholesky_.get(); }

 private:
  LevenbergMarquardtOptions options_;
  std::unique_ptr<NormalEquations> equations_;
  std::unique_ptr<NormalEquations> candidate_;  // linearized at the trial step
  std::unique_ptr<SparseCholesky> cholesky_;
};

}  // namespace kinograph::graph

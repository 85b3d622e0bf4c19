#pragma once
// Batch Gauss–Newton on the sparse normal equations with CHOLMOD.
#include <memory>

#include "kinograph/graph/factor_graph.h"
#include "kinograph/graph/optimization_result.h"
#include "kinograph/graph/ordering.h"
#include "kinograph/graph/sparse_cholesky.h"
#include "kinograph/graph/values.h"

namespace kinograph::graph {

class NormalEquations;

/// Options of GaussNewton; tolerances as LevenbergMarquardtOptions.
struct GaussNewtonOptions {
  int max_iterations = 200;
  double relative_error_tol = 1e-5;
  double absolute_error_tol = 0;
  OrderingMethod ordering = OrderingMethod::kAmd;
  Factorization factorization = Factorization::kAuto;
  bool record_history = true;
};

/// Undamped Gauss–Newton: exact in one step on linear problems; stops with kNoDecrease if a
/// full step increases the error and kSingular if H is not positive definite. Caches structure
/// like LevenbergMarquardt.
class GaussNewton {
 public:
  explicit GaussNewton(GaussNewtonOptions options = {});
  ~GaussNewton();

  /// Minimizes from `values` in place (kept at the best point on failure).
  OptimizationResult optimize(const FactorGraph& graph, Values& values);

 private:
  GaussNewtonOptions options_;
  std::unique_ptr<NormalEquations> equations_;
  std::unique_ptr<SparseCholesky> cholesky_;
};

}  // namespace kinograph::graph

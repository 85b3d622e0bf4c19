#pragma once
// What Levenberg–Marquardt needs of a Cholesky factorization of H + λD whose pattern is fixed:
// write the values, factorize, solve. Implemented by CHOLMOD (SparseCholesky) and by a dense
// envelope factorization for banded trajectory graphs (EnvelopeCholesky).
#include <Eigen/Core>

namespace kinograph::graph {

/// A reusable factorization of an n×n SPD matrix given as its upper triangle in compressed
/// columns (sorted row indices), with no allocation after construction.
class CholeskyFactor {
 public:
  virtual ~CholeskyFactor() = default;
  /// Numerical values of A's upper triangle, in pattern order; written before factorize().
  virtual double* values() = 0;
  /// Numeric factorization of the current values. False if A is not positive definite; then
  /// failed_column() is the column where it broke down.
  virtual bool factorize() = 0;
  virtual int failed_column() const = 0;
  /// Solves A x = b with the last factorization.
  virtual void solve(const Eigen::Ref<const Eigen::VectorXd>& b, Eigen::Ref<Eigen::VectorXd> x) = 0;
};

}  // namespace kinograph::graph

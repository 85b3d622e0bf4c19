#pragma once
// CHOLMOD on a symmetric positive definite matrix whose pattern is fixed: symbolic analysis
// once, numeric refactorization and solves many times, no allocation after the first solve.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "kinograph/graph/cholesky_factor.h"

struct cholmod_common_struct;
struct cholmod_sparse_struct;
struct cholmod_factor_struct;
struct cholmod_dense_struct;

namespace kinograph::graph {

/// How H is factorized. kSupernodal and kSimplicial are CHOLMOD's two forms in the solver's
/// ordering. kEnvelope is a dense LLᵀ within the envelope of H in the variables' natural (slot)
/// order (EnvelopeCholesky), which suits trajectory graphs stored in time order. kAuto (used by
/// LevenbergMarquardt) takes the envelope when it adds little fill to H in that order
/// (envelope_wins), else CHOLMOD's own flop-count rule (supernodal when the average flops per
/// nonzero of L is at least 40).
enum class Factorization { kAuto, kSupernodal, kSimplicial, kEnvelope };

/// "auto", "supernodal", "simplicial", "envelope".
std::string to_string(Factorization f);

/// A CHOLMOD factorization of an n×n SPD matrix A given as its upper triangle in compressed
/// columns (sorted row indices). The caller writes values() and calls factorize().
class SparseCholesky final : public CholeskyFactor {
 public:
  /// Copies the pattern and runs the symbolic analysis with the natural order (the caller orders
  /// the matrix already). Throws std::runtime_error if CHOLMOD fails to analyze.
  SparseCholesky(int n, const std::vector<int>& col_ptr, const std::vector<int>& row_idx,
                 Factorization factorization);
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  /// Numerical values of A's upper triangle, in pattern order.
  double* values() override;
  int nnz() const { return static_cast<int>(row_idx_.size()); }
  int rows() const { return n_; }

  /// Numeric factorization of the current values. False if A is not positive definite; then
  /// failed_column() is the column where it broke down.
  bool factorize() override;
  int failed_column() const override { return failed_column_; }
  /// Solves A x = b with the last factorization. Allocation-free for the simplicial form; CHOLMOD's
  /// supernodal factorization and solve allocate internally on every call.
  void solve(const Eigen::Ref<const Eigen::VectorXd>& b, Eigen::Ref<Eigen::VectorXd> x) override;

  /// Whether CHOLMOD chose (or was told) the supernodal form, and nnz(L).
  bool is_supernodal() const;
  double factor_nnz() const;

 private:
  int n_;
  std::vector<int> col_ptr_;
  std::vector<int> row_idx_;
  cholmod_common_struct* common_ = nullptr;
  cholmod_sparse_struct* A_ = nullptr;
  cholmod_factor_struct* L_ = nullptr;
  cholmod_dense_struct* B_ = nullptr;
  cholmod_dense_struct* X_ = nullptr;
  cholmod_dense_struct* Y_ = nullptr;
  cholmod_dense_struct* E_ = nullptr;
  int failed_column_ = -1;
  bool identity_perm_ = false;  // CHOLMOD kept the caller's order (no postordering)
};

}  // namespace kinograph::graph

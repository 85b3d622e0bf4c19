#pragma once
// Dense Cholesky LLᵀ inside the envelope (profile) of a symmetric matrix: row j of L is stored
// from its first nonzero column to the diagonal, and no fill falls outside. For a trajectory
// graph in time order the envelope is a band of about two states, so the factorization is a
// sequence of short dense products, several times cheaper than a general sparse one.
#include <Eigen/Core>
#include <vector>

#include "kinograph/graph/cholesky_factor.h"

namespace kinograph::graph {

/// LLᵀ of an n×n SPD matrix within its row envelope, in the matrix's own order.
class EnvelopeCholesky final : public CholeskyFactor {
 public:
  /// Takes the pattern of A's upper triangle (compressed columns, sorted row indices, each
  /// column's diagonal present). Throws std::invalid_argument if a column lacks its diagonal.
  EnvelopeCholesky(int n, const std::vector<int>& col_ptr, const std::vector<int>& row_idx);

  /// Floating-point multiply-adds of one factorization (Σ over rows of their dot products).
  static double flops(int n, const std::vector<int>& col_ptr, const std::vector<int>& row_idx);

  double* values() override { return values_.data(); }
  bool factorize() override;
  int failed_column() const override { return failed_column_; }
  void solve(const Eigen::Ref<const Eigen::VectorXd>& b, Eigen::Ref<Eigen::VectorXd> x) override;

  /// Whether the envelope factorization of this pattern costs at most a few times the
  /// multiply-adds a factorization without any fill would (true for banded patterns).
  static bool wins(int n, const std::vector<int>& col_ptr, const std::vector<int>& row_idx);

  // L is stored by groups of kGroupRows consecutive rows, each group from the first column of
  // any of its rows to its last row, column-major: a column of a group is a short contiguous
  // vector, so the factorization's inner loop updates every row of a group at once.
  static constexpr int kGroupRows = 4;
  // L(j, c) for c at or right of the first column of j's group.
  double& entry(int j, int c) {
    const int g = j / kGroupRows;
    return env_[static_cast<size_t>(group_start_[g] + (c - group_first_[g]) * kGroupRows +
                                    j % kGroupRows)];
  }

  int n_;
  std::vector<int> group_first_;    // group g: first column stored (its rows' smallest first)
  std::vector<long> group_start_;   // group g: offset of its first stored column in env_
  std::vector<long> value_at_;      // A's entry p (pattern order): its place in env_
  std::vector<double> values_;      // A's upper triangle, pattern order
  std::vector<double> env_;         // L by groups of rows
  std::vector<double> inv_diagonal_;  // 1 / L(j, j)
  int failed_column_ = -1;
};

}  // namespace kinograph::graph

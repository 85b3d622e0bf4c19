#include "kinograph/graph/envelope_cholesky.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kinograph::graph {

namespace {
// A pivot this small relative to the diagonal of A means H is singular to working precision
// (the same test as SparseCholesky's).
constexpr double kPivotTolerance = 1e-14;

double dot(const double* a, const double* b, int n) {
  return n > 0 ? Eigen::Map<const Eigen::VectorXd>(a, n).dot(Eigen::Map<const Eigen::VectorXd>(b, n))
               : 0.0;
}
}  // namespace

EnvelopeCholesky::EnvelopeCholesky(int n, const std::vector<int>& col_ptr,
                                   const std::vector<int>& row_idx)
    : n_(n), col_ptr_(col_ptr), row_idx_(row_idx), first_(n), start_(n + 1) {
  start_[0] = 0;
  for (int j = 0; j < n; ++j) {
    // Column j of the upper triangle is row j of the lower one: its first row is the row's
    // first column, its last the diagonal.
    if (col_ptr[j + 1] == col_ptr[j] || row_idx[col_ptr[j + 1] - 1] != j) {
      throw std::invalid_argument("EnvelopeCholesky: column " + std::to_string(j) +
                                  " has no diagonal entry");
    }
    first_[j] = row_idx[col_ptr[j]];
    start_[j + 1] = start_[j] + (j - first_[j] + 1);
  }
  values_.assign(row_idx.size(), 0.0);
  env_.assign(static_cast<size_t>(start_[n]), 0.0);
}

double EnvelopeCholesky::flops(int n, const std::vector<int>& col_ptr,
                               const std::vector<int>& row_idx) {
  std::vector<int> first(n);
  for (int j = 0; j < n; ++j) first[j] = col_ptr[j + 1] > col_ptr[j] ? row_idx[col_ptr[j]] : j;
  double total = 0;
  for (int j = 0; j < n; ++j) {
    for (int k = first[j]; k <= j; ++k) total += k - std::max(first[j], first[k]) + 1;
  }
  return total;
}

bool EnvelopeCholesky::wins(int n, const std::vector<int>& col_ptr,
                            const std::vector<int>& row_idx) {
  // Within this factor of the fill-free count, the envelope's contiguous dot products beat a
  // general sparse factorization's indexed updates.
  constexpr double kMaxFillRatio = 4;
  double fill_free = 0;
  for (int j = 0; j < n; ++j) {
    const double h = col_ptr[j + 1] - col_ptr[j];
    fill_free += 0.5 * h * (h + 1);
  }
  return flops(n, col_ptr, row_idx) <= kMaxFillRatio * fill_free;
}

bool EnvelopeCholesky::factorize() {
  failed_column_ = -1;
  std::fill(env_.begin(), env_.end(), 0.0);
  for (int j = 0; j < n_; ++j) {
    double* row = env_.data() + start_[j] - first_[j];  // row[k] = L(j, k)
    for (int p = col_ptr_[j]; p < col_ptr_[j + 1]; ++p) row[row_idx_[p]] = values_[p];
  }
  for (int j = 0; j < n_; ++j) {
    const int fj = first_[j];
    double* Lj = env_.data() + start_[j] - fj;
    for (int k = fj; k < j; ++k) {
      const int fk = first_[k];
      const double* Lk = env_.data() + start_[k] - fk;
      const int from = std::max(fj, fk);
      Lj[k] = (Lj[k] - dot(Lj + from, Lk + from, k - from)) / Lk[k];
    }
    const double a_jj = Lj[j];
    const double d = a_jj - dot(Lj + fj, Lj + fj, j - fj);
    if (!(d > kPivotTolerance * std::abs(a_jj))) {
      failed_column_ = j;
      return false;
    }
    Lj[j] = std::sqrt(d);
  }
  return true;
}

void EnvelopeCholesky::solve(const Eigen::Ref<const Eigen::VectorXd>& b,
                             Eigen::Ref<Eigen::VectorXd> x) {
  x = b;
  double* xs = x.data();
  for (int j = 0; j < n_; ++j) {  // L y = b, row by row
    const int fj = first_[j];
    const double* Lj = env_.data() + start_[j] - fj;
    xs[j] = (xs[j] - dot(Lj + fj, xs + fj, j - fj)) / Lj[j];
  }
  for (int j = n_ - 1; j >= 0; --j) {  // Lᵀ x = y, row j of L is column j of Lᵀ
    const int fj = first_[j];
    const double* Lj = env_.data() + start_[j] - fj;
    xs[j] /= Lj[j];
    const double xj = xs[j];
    Eigen::Map<Eigen::VectorXd>(xs + fj, j - fj) -= xj * Eigen::Map<const Eigen::VectorXd>(Lj + fj, j - fj);
  }
}

}  // namespace kinograph::graph

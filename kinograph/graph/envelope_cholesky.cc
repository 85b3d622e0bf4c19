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
}  // namespace

EnvelopeCholesky::EnvelopeCholesky(int n, const std::vector<int>& col_ptr,
                                   const std::vector<int>& row_idx)
    : n_(n) {
  std::vector<int> first(n);  // row j of L: first column within the envelope
  for (int j = 0; j < n; ++j) {
    // Column j of the upper triangle is row j of the lower one: its first row is the row's
    // first column, its last the diagonal.
    if (col_ptr[j + 1] == col_ptr[j] || row_idx[col_ptr[j + 1] - 1] != j) {
      throw std::invalid_argument("EnvelopeCholesky: column " + std::to_string(j) +
                                  " has no diagonal entry");
    }
    first[j] = row_idx[col_ptr[j]];
  }
  const int groups = (n + kGroupRows - 1) / kGroupRows;
  group_first_.resize(groups);
  group_start_.resize(groups + 1);
  group_start_[0] = 0;
  for (int g = 0; g < groups; ++g) {
    const int r0 = g * kGroupRows, r1 = std::min(n, r0 + kGroupRows);
    group_first_[g] = *std::min_element(first.begin() + r0, first.begin() + r1);
    group_start_[g + 1] =
        group_start_[g] + static_cast<long>(r0 + kGroupRows - group_first_[g]) * kGroupRows;
  }
  values_.assign(row_idx.size(), 0.0);
  env_.assign(static_cast<size_t>(group_start_[groups]), 0.0);
  value_at_.resize(row_idx.size());
  for (int j = 0; j < n; ++j) {
    for (int p = col_ptr[j]; p < col_ptr[j + 1]; ++p) {
      value_at_[p] = &entry(j, row_idx[p]) - env_.data();
    }
  }
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
  for (size_t p = 0; p < values_.size(); ++p) env_[static_cast<size_t>(value_at_[p])] = values_[p];
  using Column = Eigen::Matrix<double, kGroupRows, 1>;
  const int groups = static_cast<int>(group_first_.size());
  for (int g = 0; g < groups; ++g) {
    const int r0 = g * kGroupRows, rows = std::min(n_, r0 + kGroupRows) - r0;
    const int F = group_first_[g];
    double* B = env_.data() + group_start_[g];  // B + kGroupRows·(c − F): column c of the group
    // Left-looking, column by column: column k of the group's rows needs row k of L up to k.
    for (int k = F; k < r0 + rows; ++k) {
      const int h = k / kGroupRows;
      const double* Lk = env_.data() + group_start_[h] + k % kGroupRows;  // stride kGroupRows
      const int Fh = group_first_[h];
      const int from = std::max(F, Fh);
      // acc = Σ_c B(:, c) L(k, c) over c in [from, k), in two chains for throughput.
      Column acc0 = Column::Zero(), acc1 = Column::Zero();
      int c = from;
      for (; c + 1 < k; c += 2) {
        acc0.noalias() += Eigen::Map<const Column>(B + kGroupRows * (c - F)) *
                          Lk[kGroupRows * (c - Fh)];
        acc1.noalias() += Eigen::Map<const Column>(B + kGroupRows * (c + 1 - F)) *
                          Lk[kGroupRows * (c + 1 - Fh)];
      }
      if (c < k) {
        acc0.noalias() += Eigen::Map<const Column>(B + kGroupRows * (c - F)) *
                          Lk[kGroupRows * (c - Fh)];
      }
      acc0 += acc1;
      double* Bk = B + kGroupRows * (k - F);
      if (k < r0) {
        const double l_kk = Lk[kGroupRows * (k - Fh)];
        for (int i = 0; i < rows; ++i) Bk[i] = (Bk[i] - acc0[i]) / l_kk;
        continue;
      }
      // k is the group's own row i0: its diagonal, then the rows below it in the group.
      const int i0 = k - r0;
      const double a_kk = Bk[i0];
      const double d = a_kk - acc0[i0];
      if (!(d > kPivotTolerance * std::abs(a_kk))) {
        failed_column_ = k;
        return false;
      }
      const double l_kk = std::sqrt(d);
      Bk[i0] = l_kk;
      for (int i = i0 + 1; i < rows; ++i) Bk[i] = (Bk[i] - acc0[i]) / l_kk;
    }
  }
  return true;
}

void EnvelopeCholesky::solve(const Eigen::Ref<const Eigen::VectorXd>& b,
                             Eigen::Ref<Eigen::VectorXd> x) {
  using Column = Eigen::Matrix<double, kGroupRows, 1>;
  x = b;
  double* xs = x.data();
  const int groups = static_cast<int>(group_first_.size());
  // L y = b by groups: the columns left of a group at once, then its own triangle.
  for (int g = 0; g < groups; ++g) {
    const int r0 = g * kGroupRows, rows = std::min(n_, r0 + kGroupRows) - r0;
    const int F = group_first_[g];
    const double* B = env_.data() + group_start_[g];
    Column acc = Column::Zero();
    for (int c = F; c < r0; ++c) {
      acc.noalias() += Eigen::Map<const Column>(B + kGroupRows * (c - F)) * xs[c];
    }
    for (int i = 0; i < rows; ++i) {
      double s = xs[r0 + i] - acc[i];
      for (int m = 0; m < i; ++m) s -= B[kGroupRows * (r0 + m - F) + i] * xs[r0 + m];
      xs[r0 + i] = s / B[kGroupRows * (r0 + i - F) + i];
    }
  }
  // Lᵀ x = y by groups from the last: its own triangle, then the columns left of it at once.
  for (int g = groups - 1; g >= 0; --g) {
    const int r0 = g * kGroupRows, rows = std::min(n_, r0 + kGroupRows) - r0;
    const int F = group_first_[g];
    const double* B = env_.data() + group_start_[g];
    Column xg = Column::Zero();
    for (int i = rows - 1; i >= 0; --i) {
      double s = xs[r0 + i];
      for (int m = i + 1; m < rows; ++m) s -= B[kGroupRows * (r0 + i - F) + m] * xg[m];
      xg[i] = s / B[kGroupRows * (r0 + i - F) + i];
      xs[r0 + i] = xg[i];
    }
    for (int c = F; c < r0; ++c) {
      xs[c] -= Eigen::Map<const Column>(B + kGroupRows * (c - F)).dot(xg);
    }
  }
}

}  // namespace kinograph::graph

#include "kinograph/graph/envelope_cholesky.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

namespace kinograph::graph {

namespace {
// A pivot this small relative to the diagonal of A means H is singular to working precision
// (the same test as SparseCholesky's).
constexpr double kPivotTolerance = 1e-14;

constexpr int G = EnvelopeCholesky::kGroupRows;
static_assert(G == 4, "a column of a group is one vector of four doubles");

// A column of a group: one AVX register, or two SSE2 ones.
typedef double Column __attribute__((vector_size(4 * sizeof(double))));

// Loads and stores a column (by pointer: a vector by value would change the calling convention
// between the clones).
void load(Column* v, const double* p) { std::memcpy(v, p, sizeof *v); }
void store(double* p, const Column* v) { std::memcpy(p, v, sizeof *v); }

// The factorization proper on L's storage by groups (see EnvelopeCholesky's members), A in
// place; returns the failed column or −1. A free function so that it can be cloned for AVX2
// (the clone chosen when the library loads); both clones round alike (no fused multiply-add).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("avx2", "default")))
#endif
int factorize_groups(int n, int groups, const int* group_first, const long* group_start,
                     double* env, double* inv_diagonal) {
  for (int g = 0; g < groups; ++g) {
    const int r0 = g * G, rows = std::min(n, r0 + G) - r0;
    const int F = group_first[g];
    double* B = env + group_start[g];  // B + G·(c − F): column c of the group
    // Left-looking: the group's columns left of its own rows come four at a time, those of an
    // earlier group h's rows, each needing L's rows of group h up to it.
    for (int h = F / G; h < g; ++h) {
      const int rh = h * G, Fh = group_first[h];
      const double* Lh = env + group_start[h];  // Lh + G·(c − Fh): column c of h
      // acc[j](i) = Σ_c L(r0 + i, c) L(rh + j, c) over the columns both have left of rh.
      Column acc[G] = {};
      for (int c = std::max(F, Fh); c < rh; ++c) {
        Column b;
        load(&b, B + G * (c - F));
        const double* l = Lh + G * (c - Fh);
        for (int j = 0; j < G; ++j) acc[j] += b * l[j];
      }
      // Group h's own columns in turn (columns left of F are zero), each kept in a register
      // for the next; a reciprocal keeps the division off that chain.
      Column x[G];
      for (int j = 0; j < G; ++j) {
        const int k = rh + j;
        x[j] = Column{};
        if (k < F) continue;
        Column a = acc[j];
        for (int m = 0; m < j; ++m) a += x[m] * Lh[G * (rh + m - Fh) + j];
        load(&x[j], B + G * (k - F));
        x[j] = (x[j] - a) * inv_diagonal[k];
        store(B + G * (k - F), &x[j]);
      }
    }
    // The group's own rows: its diagonal, then the rows below it in the group (a last group's
    // missing rows hold zeros throughout).
    Column acc[G] = {};
    for (int c = F; c < r0; ++c) {
      Column b;
      load(&b, B + G * (c - F));
      for (int j = 0; j < G; ++j) acc[j] += b * b[j];
    }
    Column x[G];
    for (int j = 0; j < rows; ++j) {
      const int k = r0 + j;
      Column a = acc[j];
      for (int m = 0; m < j; ++m) a += x[m] * x[m][j];
      const double a_kk = B[G * (k - F) + j];
      load(&x[j], B + G * (k - F));
      x[j] -= a;
      const double d = x[j][j];
      if (!(d > kPivotTolerance * std::abs(a_kk))) return k;
      const double l_kk = std::sqrt(d);
      inv_diagonal[k] = 1 / l_kk;
      x[j] *= inv_diagonal[k];
      for (int i = 0; i < j; ++i) x[j][i] = 0;  // above the diagonal
      x[j][j] = l_kk;
      store(B + G * (k - F), &x[j]);
    }
  }
  return -1;
}
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
  inv_diagonal_.assign(n, 0.0);
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
  std::fill(env_.begin(), env_.end(), 0.0);
  for (size_t p = 0; p < values_.size(); ++p) env_[static_cast<size_t>(value_at_[p])] = values_[p];
  failed_column_ = factorize_groups(n_, static_cast<int>(group_first_.size()), group_first_.data(),
                                    group_start_.data(), env_.data(), inv_diagonal_.data());
  return failed_column_ < 0;
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
      xs[r0 + i] = s * inv_diagonal_[r0 + i];
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
      xg[i] = s * inv_diagonal_[r0 + i];
      xs[r0 + i] = xg[i];
    }
    for (int c = F; c < r0; ++c) {
      xs[c] -= Eigen::Map<const Column>(B + kGroupRows * (c - F)).dot(xg);
    }
  }
}

}  // namespace kinograph::graph

#include "kinograph/graph/banded_system.h"

#include <algorithm>

namespace kinograph::graph {

bool BandedSystem::prepare(const std::vector<int>& free_slots, const std::vector<int>& dims,
                           const std::vector<LinearizedFactor>& linearized,
                           const std::vector<int>& factors) {
  // The factors' variables in order, with a separator: unchanged, the pattern is too.
  signature_scratch_.clear();
  for (int f : factors) {
    const std::vector<int>& vars = linearized[f].vars;
    signature_scratch_.insert(signature_scratch_.end(), vars.begin(), vars.end());
    signature_scratch_.push_back(-1);
  }
  if (signature_scratch_ == signature_ && free_slots == slots_ && dims == dim_) {
    return cholesky_ != nullptr;  // the same pattern, which suits the envelope or not
  }
  std::swap(signature_, signature_scratch_);
  const int slots = static_cast<int>(dims.size());
  std::vector<int> column(slots, -1);
  int n = 0;
  for (int s : free_slots) {
    column[s] = n;
    n += dims[s];
  }
  // Every factor's variables are neighbours of each other; a factor without an active row
  // counts too, so that the pattern stays when it turns active.
  std::vector<std::vector<int>> lower(slots);
  for (int f : factors) {
    const std::vector<int>& vars = linearized[f].vars;
    for (int b : vars) {
      for (int a : vars) {
        if (column[a] < column[b]) lower[b].push_back(a);
      }
    }
  }
  for (std::vector<int>& l : lower) {
    std::sort(l.begin(), l.end(), [&](int x, int y) { return column[x] < column[y]; });
    l.erase(std::unique(l.begin(), l.end()), l.end());
  }
  if (cholesky_ && column == column_ && dims == dim_ && lower == lower_) return true;

  slots_ = free_slots;
  column_ = std::move(column);
  dim_ = dims;
  lower_ = std::move(lower);
  lower_rows_.assign(slots, {});
  diagonal_row_.assign(slots, 0);
  col_ptr_.assign(1, 0);
  row_idx_.clear();
  for (int b : slots_) {
    std::vector<int>& offsets = lower_rows_[b];
    int rows = 0;
    for (int a : lower_[b]) {
      offsets.push_back(rows);
      rows += dim_[a];
    }
    diagonal_row_[b] = rows;
    for (int j = 0; j < dim_[b]; ++j) {
      for (int a : lower_[b]) {
        for (int r = 0; r < dim_[a]; ++r) row_idx_.push_back(column_[a] + r);
      }
      for (int r = 0; r <= j; ++r) row_idx_.push_back(column_[b] + r);
      col_ptr_.push_back(static_cast<int>(row_idx_.size()));
    }
  }
  cholesky_.reset();
  if (n == 0 || !EnvelopeCholesky::wins(n, col_ptr_, row_idx_)) return false;
  cholesky_ = std::make_unique<EnvelopeCholesky>(n, col_ptr_, row_idx_);
  h_.assign(row_idx_.size(), 0.0);
  g_.resize(n);
  rhs_.resize(n);
  x_.resize(n);
  return true;
}

int BandedSystem::row_offset(int b, int a) const {
  const std::vector<int>& l = lower_[b];
  const auto it = std::lower_bound(l.begin(), l.end(), a,
                                   [&](int x, int y) { return column_[x] < column_[y]; });
  return lower_rows_[b][static_cast<size_t>(it - l.begin())];
}

void BandedSystem::add_block(const Eigen::MatrixXd& H, int row, int col, int a, int b) {
  const int c0 = column_[b];
  if (a == b) {
    for (int j = 0; j < dim_[b]; ++j) {
      double* out = h_.data() + col_ptr_[c0 + j] + diagonal_row_[b];
      const double* in = H.data() + static_cast<Eigen::Index>(col + j) * H.rows() + row;
      for (int r = 0; r <= j; ++r) out[r] += in[r];
    }
    return;
  }
  const int offset = row_offset(b, a);
  for (int j = 0; j < dim_[b]; ++j) {
    double* out = h_.data() + col_ptr_[c0 + j] + offset;
    const double* in = H.data() + static_cast<Eigen::Index>(col + j) * H.rows() + row;
    for (int r = 0; r < dim_[a]; ++r) out[r] += in[r];
  }
}

void BandedSystem::assemble(const std::vector<LinearizedFactor>& linearized,
                            const std::vector<int>& factors) {
  std::fill(h_.begin(), h_.end(), 0.0);
  g_.setZero();
  for (int f : factors) {
    const LinearizedFactor& lf = linearized[f];
    if (lf.zero) continue;
    const int nv = static_cast<int>(lf.vars.size());
    for (int k = 0; k < nv; ++k) {
      const int b = lf.vars[k];
      g_.segment(column_[b], dim_[b]) += lf.g.segment(lf.offsets[k], dim_[b]);
      for (int i = 0; i < nv; ++i) {
        const int a = lf.vars[i];
        if (column_[a] <= column_[b]) add_block(lf.H, lf.offsets[i], lf.offsets[k], a, b);
      }
    }
  }
}

bool BandedSystem::solve(const Eigen::VectorXd* damping, const std::vector<int>& offsets,
                         Eigen::VectorXd& delta, int* bad_slot) {
  double* A = cholesky_->values();
  std::copy(h_.begin(), h_.end(), A);
  if (damping != nullptr) {
    for (int s : slots_) {
      for (int j = 0; j < dim_[s]; ++j) {
        A[col_ptr_[column_[s] + j + 1] - 1] += (*damping)[offsets[s] + j];  // the diagonal
      }
    }
  }
  if (!cholesky_->factorize()) {
    if (bad_slot != nullptr) {
      const int c = cholesky_->failed_column();
      for (int s : slots_) {
        if (column_[s] <= c && c < column_[s] + dim_[s]) *bad_slot = s;
      }
    }
    return false;
  }
  rhs_ = -g_;
  cholesky_->solve(rhs_, x_);
  for (int s : slots_) delta.segment(offsets[s], dim_[s]) = x_.segment(column_[s], dim_[s]);
  return true;
}

}  // namespace kinograph::graph

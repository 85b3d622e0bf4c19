#include "kinograph/graph/sparse_cholesky.h"

#include <cholmod.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kinograph::graph {

std::string to_string(Factorization f) {
  switch (f) {
    case Factorization::kAuto:
      return "auto";
    case Factorization::kSupernodal:
      return "supernodal";
    case Factorization::kSimplicial:
      return "simplicial";
    case Factorization::kEnvelope:
      return "envelope";
  }
  return "unknown";
}

namespace {
// A pivot this small relative to the diagonal of A means H is singular to working precision.
constexpr double kPivotTolerance = 1e-14;
}  // namespace

SparseCholesky::SparseCholesky(int n, const std::vector<int>& col_ptr,
                               const std::vector<int>& row_idx, Factorization factorization)
    : n_(n), col_ptr_(col_ptr), row_idx_(row_idx) {
  common_ = new cholmod_common;
  cholmod_start(common_);
  common_->print = 0;
  // The caller has ordered the matrix; skipping CHOLMOD's own ordering and postorder keeps
  // L->Perm the identity, so every refactorization reads A in place instead of permuting it.
  common_->nmethods = 1;
  common_->method[0].ordering = CHOLMOD_NATURAL;
  common_->postorder = 0;
  common_->final_ll = 0;  // simplicial stays LDLᵀ
  switch (factorization) {
    case Factorization::kAuto:
      common_->supernodal = CHOLMOD_AUTO;
      break;
    case Factorization::kSupernodal:
      common_->supernodal = CHOLMOD_SUPERNODAL;
      break;
    case Factorization::kSimplicial:
    case Factorization::kEnvelope:  // not CHOLMOD's; a caller that falls back gets simplicial
      common_->supernodal = CHOLMOD_SIMPLICIAL;
      break;
  }
  A_ = cholmod_allocate_sparse(n, n, row_idx.size(), 1, 1, 1, CHOLMOD_REAL, common_);
  if (A_ == nullptr) throw std::runtime_error("CHOLMOD could not allocate the matrix");
  std::copy(col_ptr.begin(), col_ptr.end(), static_cast<int*>(A_->p));
  std::copy(row_idx.begin(), row_idx.end(), static_cast<int*>(A_->i));
  std::fill_n(static_cast<double*>(A_->x), row_idx.size(), 0.0);
  L_ = cholmod_analyze(A_, common_);
  if (L_ == nullptr || common_->status < CHOLMOD_OK) {
    throw std::runtime_error("CHOLMOD symbolic analysis failed (status " +
                             std::to_string(common_->status) + ")");
  }
  B_ = cholmod_allocate_dense(n, 1, n, CHOLMOD_REAL, common_);
  identity_perm_ = true;
  const int* perm = static_cast<const int*>(L_->Perm);
  for (int i = 0; perm != nullptr && i < n; ++i) identity_perm_ = identity_perm_ && perm[i] == i;
}

SparseCholesky::~SparseCholesky() {
  if (common_ == nullptr) return;
  cholmod_free_dense(&B_, common_);
  cholmod_free_dense(&X_, common_);
  cholmod_free_dense(&Y_, common_);
  cholmod_free_dense(&E_, common_);
  cholmod_free_factor(&L_, common_);
  cholmod_free_sparse(&A_, common_);
  cholmod_finish(common_);
  delete common_;
}

double* SparseCholesky::values() { return static_cast<double*>(A_->x); }

bool SparseCholesky::factorize() {
  failed_column_ = -1;
  const int ok = cholmod_factorize(A_, L_, common_);
  if (!ok || common_->status == CHOLMOD_NOT_POSDEF) {
    failed_column_ = static_cast<int>(std::min<size_t>(L_->minor, n_ - 1));
    return false;
  }
  if (!L_->is_super) {
    // LDLᵀ only stops at exactly zero pivots; reject tiny or negative ones too, since H + λD is
    // positive semidefinite in exact arithmetic and such pivots mean it is singular.
    const int* Lp = static_cast<const int*>(L_->p);
    const double* Lx = static_cast<const double*>(L_->x);
    const int* Ap = col_ptr_.data();
    const double* Ax = static_cast<const double*>(A_->x);
    for (int j = 0; j < n_; ++j) {
      const double a_jj = Ax[Ap[j + 1] - 1];  // upper triangle, sorted: diagonal is last
      const double d = Lx[Lp[j]];
      if (!(d > kPivotTolerance * std::abs(a_jj))) {
        failed_column_ = j;
        return false;
      }
    }
  }
  return true;
}

void SparseCholesky::solve(const Eigen::Ref<const Eigen::VectorXd>& b,
                           Eigen::Ref<Eigen::VectorXd> x) {
  if (!L_->is_super && identity_perm_) {
    // Simplicial factor in the caller's order: the two triangular solves directly on L's
    // columns (cholmod_solve2 would allocate on every call).
    const int* Lp = static_cast<const int*>(L_->p);
    const int* Li = static_cast<const int*>(L_->i);
    const int* Lnz = static_cast<const int*>(L_->nz);
    const double* Lx = static_cast<const double*>(L_->x);
    const bool ll = L_->is_ll != 0;
    x = b;
    for (int j = 0; j < n_; ++j) {  // L y = b (diagonal first in each column)
      const int p0 = Lp[j];
      if (ll) x[j] /= Lx[p0];
      const double xj = x[j];
      for (int p = p0 + 1; p < p0 + Lnz[j]; ++p) x[Li[p]] -= Lx[p] * xj;
    }
    if (!ll) {
      for (int j = 0; j < n_; ++j) x[j] /= Lx[Lp[j]];  // D z = y
    }
    for (int j = n_ - 1; j >= 0; --j) {  // Lᵀ x = z
      const int p0 = Lp[j];
      double xj = x[j];
      for (int p = p0 + 1; p < p0 + Lnz[j]; ++p) xj -= Lx[p] * x[Li[p]];
      x[j] = ll ? xj / Lx[p0] : xj;
    }
    return;
  }
  std::copy_n(b.data(), n_, static_cast<double*>(B_->x));
  cholmod_solve2(CHOLMOD_A, L_, B_, nullptr, &X_, nullptr, &Y_, &E_, common_);
  std::copy_n(static_cast<const double*>(X_->x), n_, x.data());
}

bool SparseCholesky::is_supernodal() const { return L_->is_super != 0; }

double SparseCholesky::factor_nnz() const { return common_->lnz; }

}  // namespace kinograph::graph

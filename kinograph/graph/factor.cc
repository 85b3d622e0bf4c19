#include "kinograph/graph/factor.h"

#include <cxxabi.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <typeinfo>
#include <vector>

namespace kinograph::graph {

Factor::Factor(std::vector<Key> keys, std::vector<int> dims, int residual_dim, NoiseModelPtr noise)
    : keys_(std::move(keys)), dims_(std::move(dims)), residual_dim_(residual_dim), cols_(0) {
  if (keys_.empty()) throw std::invalid_argument("Factor: no keys");
  if (keys_.size() != dims_.size()) {
    throw std::invalid_argument("Factor: " + std::to_string(keys_.size()) + " keys but " +
                                std::to_string(dims_.size()) + " dimensions");
  }
  if (residual_dim_ < 1) throw std::invalid_argument("Factor: residual dimension must be >= 1");
  for (size_t i = 0; i < keys_.size(); ++i) {
    if (dims_[i] < 1) {
      throw std::invalid_argument("Factor: key " + keys_[i].to_string() + " has dimension " +
                                  std::to_string(dims_[i]));
    }
    for (size_t j = 0; j < i; ++j) {
      if (keys_[j] == keys_[i]) {
        throw std::invalid_argument("Factor: key " + keys_[i].to_string() + " appears twice");
      }
    }
    offsets_.push_back(cols_);
    cols_ += dims_[i];
  }
  set_noise(std::move(noise));
}

void Factor::rename_keys(const std::function<Key(Key)>& rename) {
  std::vector<Key> keys(keys_.size());
  for (size_t i = 0; i < keys_.size(); ++i) {
    keys[i] = rename(keys_[i]);
    for (size_t j = 0; j < i; ++j) {
      if (keys[j] == keys[i]) {
        throw std::invalid_argument("Factor::rename_keys: " + keys_[j].to_string() + " and " +
                                    keys_[i].to_string() + " would both be " + keys[i].to_string());
      }
    }
  }
  keys_ = std::move(keys);
}

std::string Factor::name() const {
  const char* mangled = typeid(*this).name();
  int status = 0;
  std::unique_ptr<char, void (*)(void*)> demangled(
      abi::__cxa_demangle(mangled, nullptr, nullptr, &status), std::free);
  return status == 0 && demangled ? std::string(demangled.get()) : std::string(mangled);
}

void Factor::set_noise(NoiseModelPtr noise) {
  if (noise && noise->dim() != residual_dim_) {
    throw std::invalid_argument("Factor " + name() + ": noise model of dimension " +
                                std::to_string(noise->dim()) + " for residual of dimension " +
                                std::to_string(residual_dim_));
  }
  noise_ = std::move(noise);
  jacobian_changed();
}

void Factor::jacobian_changed() {
  static std::atomic<long> last_version{0};
  jacobian_version_ = ++last_version;
}

void Factor::whitened(const double* const* x, Eigen::Ref<Eigen::VectorXd> r,
                      Eigen::Ref<Eigen::MatrixXd>* J, RowSupport* support) const {
  const FactorValues xv(x, dims_.data());
  if (J == nullptr) {
    evaluate(xv, r, nullptr);
    if (noise_) noise_->whiten_residual(r);
    return;
  }
  if (support == nullptr || noise_ || !writes_listed_rows_only()) J->setZero();
  if (support != nullptr) support->all = true;
  // A noise model may mix rows, so only an unwhitened factor may leave rows out.
  const Jacobians jac(J->data(), J->rows(), J->outerStride(), offsets_.data(), dims_.data(),
                      noise_ ? nullptr : support);
  evaluate(xv, r, &jac);
  if (noise_) noise_->whiten_system(r, *J);
}

namespace {
std::vector<const double*> gather(const Factor& f, const Values& values) {
  std::vector<const double*> ptrs(f.keys().size());
  for (size_t i = 0; i < ptrs.size(); ++i) {
    const int s = values.slot(f.keys()[i]);
    if (values.dim(s) != f.dims()[i]) {
      throw std::invalid_argument("Factor " + f.name() + ": key " + f.keys()[i].to_string() +
                                  " has dimension " + std::to_string(values.dim(s)) +
                                  " in Values, factor expects " + std::to_string(f.dims()[i]));
    }
    ptrs[i] = values.vector().data() + values.offset(s);
  }
  return ptrs;
}
}  // namespace

void Factor::linearize(const Values& values, Eigen::VectorXd& r, Eigen::MatrixXd& J) const {
  const auto ptrs = gather(*this, values);
  r.setZero(residual_dim_);
  J.resize(residual_dim_, cols_);
  Eigen::Ref<Eigen::MatrixXd> ref(J);
  whitened(ptrs.data(), r, &ref);
}

void Factor::whitened_residual(const Values& values, Eigen::VectorXd& r) const {
  const auto ptrs = gather(*this, values);
  r.setZero(residual_dim_);
  whitened(ptrs.data(), r, nullptr);
}

double Factor::error(const Values& values) const {
  Eigen::VectorXd r;
  whitened_residual(values, r);
  return 0.5 * r.squaredNorm();
}

bool all_finite(const Eigen::Ref<const Eigen::MatrixXd>& M) {
  return std::isfinite((M.array() * 0.0).sum());
}

int compact_nonzero_rows(Eigen::Ref<Eigen::MatrixXd> J, Eigen::Ref<Eigen::VectorXd> r,
                         bool* finite, const RowSupport* support) {
  // J is column-major: rows are found and moved column by column, never by strided row scans.
  // A row of finite entries is all zero exactly when the sum of its magnitudes is zero.
  const Eigen::Index m = J.rows();
  thread_local Eigen::ArrayXd magnitude;
  thread_local std::vector<Eigen::Index> rows;
  rows.clear();
  if (support != nullptr && !support->all) {
    // Only the listed rows, each summed in the same column order as below.
    const auto& listed = support->rows;
    const Eigen::Index n = static_cast<Eigen::Index>(listed.size());
    if (magnitude.size() < n) magnitude.resize(n);
    auto mag = magnitude.head(n);
    mag.setZero();
    for (Eigen::Index c = 0; c < J.cols(); ++c) {
      const double* col = J.col(c).data();
      for (Eigen::Index t = 0; t < n; ++t) mag[t] += std::abs(col[listed[t]]);
    }
    if (finite != nullptr) {
      // Only an overflowing sum of finite entries needs the exact test.
      *finite = true;
      for (Eigen::Index t = 0; t < n; ++t) {
        if (!std::isfinite(mag[t]) && !J.row(listed[t]).allFinite()) *finite = false;
      }
      if (!*finite) return static_cast<int>(m);
    }
    for (Eigen::Index t = 0; t < n; ++t) {
      if (mag[t] != 0) rows.push_back(listed[t]);
    }
  } else {
    if (magnitude.size() < m) magnitude.resize(m);
    auto mag = magnitude.head(m);
    mag.setZero();
    for (Eigen::Index c = 0; c < J.cols(); ++c) mag += J.col(c).array().abs();
    if (finite != nullptr) {
      // A NaN or ±inf entry makes its row's magnitude non-finite; only an overflowing sum of
      // finite entries needs the exact test.
      *finite = mag.allFinite() || all_finite(J);
      if (!*finite) return static_cast<int>(m);
    }
    for (Eigen::Index i = 0; i < m; ++i) {
      if (mag[i] != 0) rows.push_back(i);
    }
  }
  const Eigen::Index kept = static_cast<Eigen::Index>(rows.size());
  if (kept == m) return static_cast<int>(kept);
  // rows[t] >= t, so moving in increasing t never overwrites a row still to be read.
  for (Eigen::Index c = 0; c < J.cols(); ++c) {
    double* col = J.col(c).data();
    for (Eigen::Index t = 0; t < kept; ++t) col[t] = col[rows[t]];
  }
  for (Eigen::Index t = 0; t < kept; ++t) r[t] = r[rows[t]];
  return static_cast<int>(kept);
}

void jacobian_gram(const Eigen::Ref<const Eigen::MatrixXd>& J, Eigen::Ref<Eigen::MatrixXd> H,
                   bool upper_only) {
  constexpr Eigen::Index kRankUpdateColumns = 16;
  if (J.cols() < kRankUpdateColumns) {
    H.noalias() = J.transpose() * J;
    return;
  }
  H.triangularView<Eigen::Upper>().setZero();
  H.selfadjointView<Eigen::Upper>().rankUpdate(J.transpose());
  if (!upper_only) H.triangularView<Eigen::StrictlyLower>() = H.transpose();
}

}  // namespace kinograph::graph

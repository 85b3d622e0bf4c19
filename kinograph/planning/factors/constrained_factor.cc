#include "kinograph/planning/factors/constrained_factor.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace kinograph::planning {

ConstrainedFactor::ConstrainedFactor(std::vector<graph::Key> keys, std::vector<int> dims,
                                     std::vector<RowSpec> rows)
    : graph::Factor(std::move(keys), std::move(dims), static_cast<int>(rows.size())),
      rows_(std::move(rows)) {
  for (const RowSpec& r : rows_) {
    if (r.kind != RowKind::kSoft) {
      ++num_constraints_;
      if (!(r.scale > 0)) throw std::invalid_argument("constraint row scale must be positive");
    }
    if (r.kind == RowKind::kBounds && !(r.lower <= r.upper)) {
      throw std::invalid_argument("constraint row has lower bound above upper bound");
    }
  }
}

Multipliers::Multipliers(int rows, double mu)
    : penalty(mu), lower(Eigen::VectorXd::Zero(rows)), upper(Eigen::VectorXd::Zero(rows)) {}

void ConstrainedFactor::bind(std::shared_ptr<const Multipliers> m) {
  if (!m) throw std::invalid_argument(name() + ": null multipliers");
  if (m->lower.size() != residual_dim() || m->upper.size() != residual_dim()) {
    throw std::invalid_argument(name() + ": multipliers have the wrong size");
  }
  m_ = std::move(m);
  penalty_changed();
}

void ConstrainedFactor::penalty_changed() {
  if (!m_) return;
  if (!(m_->penalty > 0)) throw std::invalid_argument("penalty must be positive");
  if (m_->penalty != penalty_read_) jacobian_changed();
  penalty_read_ = m_->penalty;
}

namespace {
// The factor whose evaluate() runs on this thread (jacobian_row_needed answers for it only).
thread_local const ConstrainedFactor* evaluating = nullptr;
// Set by rows_proven_clear() during that factor's compute().
thread_local bool proven_clear = false;
// Set by clear_rows_not_measured() during the compute() that cached_compute() runs.
thread_local bool not_measured = false;

// Marks `f` as evaluating for its lifetime (also when compute() throws).
struct Evaluating {
  explicit Evaluating(const ConstrainedFactor* f) { evaluating = f; }
  ~Evaluating() { evaluating = nullptr; }
  Evaluating(const Evaluating&) = delete;
  Evaluating& operator=(const Evaluating&) = delete;
};

// The hinge terms of a bound row: a = √μ c_l + λ_l/√μ, b = √μ c_u + λ_u/√μ (on when positive).
struct Hinge {
  double a, b;
};
Hinge hinge(const RowSpec& row, double z, double sq, double lambda, double lambda_upper) {
  return {sq * (row.lower - z) / row.scale + lambda / sq,
          sq * (z - row.upper) / row.scale + lambda_upper / sq};
}
// Whether a bound row lies within its bounds without multipliers, so both hinges are off
// (the test that saves hinge()'s divisions on most collision pairs; false also on NaN).
bool hinges_off(const RowSpec& row, double z, double lambda, double lambda_upper) {
  return lambda == 0 && lambda_upper == 0 && row.lower - z <= 0 && z - row.upper <= 0;
}
}  // namespace

bool ConstrainedFactor::jacobian_row_needed(int row, double z) const {
  const RowSpec& spec = rows_[static_cast<size_t>(row)];
  if (evaluating != this || spec.kind != RowKind::kBounds) return true;
  if (hinges_off(spec, z, m_ ? m_->lower[row] : 0.0, m_ ? m_->upper[row] : 0.0)) return false;
  const Hinge h = m_ ? hinge(spec, z, std::sqrt(m_->penalty), m_->lower[row], m_->upper[row])
                     : hinge(spec, z, 1.0, 0.0, 0.0);
  return h.a > 0 || h.b > 0;
}

void ConstrainedFactor::rows_proven_clear() const {
  if (evaluating == this) proven_clear = true;
}

void ConstrainedFactor::clear_rows_not_measured() const { not_measured = true; }

bool ConstrainedFactor::bound_multipliers_zero() const {
  return !m_ || ((m_->lower.array() == 0).all() && (m_->upper.array() == 0).all());
}

void ConstrainedFactor::evaluate(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                                 const graph::Jacobians* J) const {
  // With a row list, a factor that lists the rows it writes gets J unzeroed: the rows listed
  // below that compute() did not write are zeroed here.
  graph::RowSupport* support = J != nullptr ? J->row_support() : nullptr;
  const bool unzeroed = support != nullptr && lists_written_rows_;
  if (unzeroed) support->rows.clear();
  proven_clear = false;
  {
    const Evaluating guard(this);
    cached_compute(x, e, J);
  }
  if (proven_clear) {  // what the loop below would give, without it
    e.setZero();
    if (J == nullptr) return;
    if (support != nullptr) {
      support->rows.clear();
      support->all = residual_dim() == 0;
      return;
    }
    for (size_t k = 0; k < keys().size(); ++k) J->block(static_cast<int>(k)).setZero();
    return;
  }
  thread_local std::vector<char> written;
  if (unzeroed) {
    written.assign(static_cast<size_t>(residual_dim()), 0);
    for (int i : support->rows) written[static_cast<size_t>(i)] = 1;
  }
  // An unbound factor reads μ = 1 and λ = 0 (per-thread zeros that only grow).
  thread_local Eigen::VectorXd zeros;
  if (!m_ && zeros.size() < residual_dim()) zeros.setZero(residual_dim());
  const double* lambda = m_ ? m_->lower.data() : zeros.data();
  const double* lambda_upper = m_ ? m_->upper.data() : zeros.data();
  const double sq = m_ ? std::sqrt(m_->penalty) : 1.0;
  // dr/dz of every row, applied to the Jacobian blocks column by column afterwards (blocks are
  // column-major: scaling row by row would stride through memory). Per-thread scratch that only
  // grows, so linearizing allocates nothing after the first factor of the largest size.
  thread_local Eigen::VectorXd scratch;
  if (scratch.size() < residual_dim()) scratch.resize(residual_dim());
  auto f = scratch.head(residual_dim());
  for (int i = 0; i < residual_dim(); ++i) {
    const RowSpec& row = rows_[i];
    const double z = e[i];
    switch (row.kind) {
      case RowKind::kSoft:
        f[i] = row.weight;
        e[i] = row.weight * (z - row.lower);
        break;
      case RowKind::kEquality:
        f[i] = sq / row.scale;
        e[i] = f[i] * (z - row.lower) + lambda[i] / sq;
        break;
      case RowKind::kBounds: {
        if (hinges_off(row, z, lambda[i], lambda_upper[i])) {  // what hinge() would give
          e[i] = 0.0;
          f[i] = -0.0;
          break;
        }
        const Hinge h = hinge(row, z, sq, lambda[i], lambda_upper[i]);
        e[i] = std::max(0.0, h.a) - std::max(0.0, h.b);
        f[i] = -(sq / row.scale) * ((h.a > 0 ? 1.0 : 0.0) + (h.b > 0 ? 1.0 : 0.0));
        break;
      }
    }
  }
  if (J == nullptr) return;
  // Rows whose dr/dz is zero (a bound whose hinge is off) are left out instead of zeroed when
  // the caller takes a row list: most of a collision factor's pairs are clear.
  if (support != nullptr) {
    support->rows.clear();
    for (int i = 0; i < residual_dim(); ++i) {
      if (f[i] == 0) continue;
      support->rows.push_back(i);
      if (unzeroed && !written[static_cast<size_t>(i)]) {
        for (size_t k = 0; k < keys().size(); ++k) J->block(static_cast<int>(k)).row(i).setZero();
      }
    }
    support->all = static_cast<int>(support->rows.size()) == residual_dim();
  }
  if (support == nullptr || support->all) {
    for (size_t k = 0; k < keys().size(); ++k) {
      J->block(static_cast<int>(k)).array().colwise() *= f.array();
    }
    return;
  }
  for (size_t k = 0; k < keys().size(); ++k) {
    auto block = J->block(static_cast<int>(k));
    for (Eigen::Index c = 0; c < block.cols(); ++c) {
      double* col = &block(0, c);
      for (int i : support->rows) col[i] *= f[i];
    }
  }
}

void ConstrainedFactor::values_at(const graph::Values& values, Eigen::VectorXd& z) const {
  z.setZero(residual_dim());
  compute_at(values, z);
}

void ConstrainedFactor::compute_at(const graph::Values& values,
                                   Eigen::Ref<Eigen::VectorXd> z) const {
  // Per-thread key pointers that only grow: the outer loop calls this for every factor.
  thread_local std::vector<const double*> ptrs;
  if (ptrs.size() < keys().size()) ptrs.resize(keys().size());
  for (size_t k = 0; k < keys().size(); ++k) ptrs[k] = values.at(keys()[k]).data();
  z.setZero();
  cached_compute(graph::FactorValues(ptrs.data(), dims().data()), z, nullptr);
}

void ConstrainedFactor::cache_evaluations() {
  if (lists_written_rows_) {
    throw std::logic_error(name() + ": a kept Jacobian needs every row written");
  }
  kept_.resize(2);
  for (Evaluation& k : kept_) {
    k.x.resize(jacobian_cols());
    k.z.resize(residual_dim());
  }
  kept_[1].J.resize(residual_dim(), jacobian_cols());
  kept_[1].filled.assign(static_cast<size_t>(residual_dim()), 0);
}

void ConstrainedFactor::list_written_rows() {
  if (kept_.size() == 2) {
    throw std::logic_error(name() + ": a kept Jacobian needs every row written");
  }
  lists_written_rows_ = true;
}

void ConstrainedFactor::cache_values() {
  kept_.resize(1);
  kept_[0].x.resize(jacobian_cols());
  kept_[0].z.resize(residual_dim());
}

void ConstrainedFactor::keep(Evaluation& k, const graph::FactorValues& x,
                             const Eigen::Ref<const Eigen::VectorXd>& z) const {
  for (size_t b = 0; b < keys().size(); ++b) {
    k.x.segment(block_offsets()[b], dims()[b]) = x[static_cast<int>(b)];
  }
  k.z = z;
  k.valid = true;
  k.clear_rows_not_measured = std::exchange(not_measured, false);
}

bool ConstrainedFactor::kept_at(const Evaluation& k, const graph::FactorValues& x) const {
  if (!k.valid || (k.clear_rows_not_measured && !bound_multipliers_zero())) return false;
  for (size_t b = 0; b < keys().size(); ++b) {
    const int i = static_cast<int>(b);
    const size_t bytes = sizeof(double) * static_cast<size_t>(dims()[b]);
    if (std::memcmp(x[i].data(), k.x.data() + block_offsets()[b], bytes) != 0) return false;
  }
  return true;
}

bool ConstrainedFactor::reusable(const graph::FactorValues& x, bool with_jacobian) const {
  const Evaluation& k = kept_[with_jacobian ? 1 : 0];
  if (!kept_at(k, x)) return false;
  if (!with_jacobian) return true;
  for (int row = 0; row < residual_dim(); ++row) {
    if (!k.filled[static_cast<size_t>(row)] && jacobian_row_needed(row, k.z[row])) return false;
  }
  return true;
}

void ConstrainedFactor::cached_compute(const graph::FactorValues& x,
                                       Eigen::Ref<Eigen::VectorXd> z,
                                       const graph::Jacobians* J) const {
  not_measured = false;
  // compute(), holding it to clear_rows_not_measured()'s contract.
  auto compute_here = [&] {
    compute(x, z, J);
    if (J != nullptr && not_measured) {
      throw std::logic_error(name() + ": rows left unmeasured in an evaluation with Jacobians");
    }
  };
  if (kept_.empty()) {
    compute_here();
    return;
  }
  if (kept_.size() == 1) {  // cache_values(): the last values, from either kind of evaluation
    Evaluation& k = kept_[0];
    if (J == nullptr && kept_at(k, x)) {
      z = k.z;
      return;
    }
    compute_here();
    keep(k, x, z);
    return;
  }
  // Values alone may come from the last linearization: the outer loop and the incremental
  // planner's stopping rule read them at the point just linearized.
  if (J == nullptr && !kept_at(kept_[0], x) && kept_at(kept_[1], x)) {
    z = kept_[1].z;
    return;
  }
  Evaluation& k = kept_[J != nullptr ? 1 : 0];
  const auto& offsets = block_offsets();
  if (reusable(x, J != nullptr)) {
    z = k.z;
    if (J != nullptr) {
      for (size_t b = 0; b < keys().size(); ++b) {
        J->block(static_cast<int>(b)) = k.J.middleCols(offsets[b], dims()[b]);
      }
    }
    return;
  }
  compute_here();
  keep(k, x, z);
  if (J == nullptr) return;
  for (size_t b = 0; b < keys().size(); ++b) {
    k.J.middleCols(offsets[b], dims()[b]) = J->block(static_cast<int>(b));
  }
  for (int row = 0; row < residual_dim(); ++row) {
    k.filled[static_cast<size_t>(row)] = jacobian_row_needed(row, z[row]) ? 1 : 0;
  }
}

namespace {
// Violation of row i in its own units: |z − t| or the bound excess (0 for soft rows).
double row_violation(const RowSpec& row, double z) {
  switch (row.kind) {
    case RowKind::kSoft:
      return 0;
    case RowKind::kEquality:
      return std::abs(z - row.lower);
    case RowKind::kBounds:
      return std::max({0.0, row.lower - z, z - row.upper});
  }
  return 0;
}

// Raw values of `f` at `values` in a per-thread buffer (valid until the next call).
Eigen::Ref<Eigen::VectorXd> raw_values(const ConstrainedFactor& f, const graph::Values& values) {
  thread_local Eigen::VectorXd z;
  if (z.size() < f.residual_dim()) z.resize(f.residual_dim());
  auto head = z.head(f.residual_dim());
  f.compute_at(values, head);
  return head;
}
}  // namespace

ConstrainedFactor::Violation ConstrainedFactor::check(const graph::Values& values) const {
  return scan(values, nullptr);
}

ConstrainedFactor::Violation ConstrainedFactor::update_multipliers(const graph::Values& values,
                                                                   Multipliers& m) const {
  if (m.lower.size() != residual_dim() || m.upper.size() != residual_dim()) {
    throw std::invalid_argument(name() + ": multipliers have the wrong size");
  }
  return scan(values, &m);
}

ConstrainedFactor::Violation ConstrainedFactor::scan(const graph::Values& values,
                                                     Multipliers* m) const {
  const bool update = m != nullptr;
  Violation v;
  if (num_constraints_ == 0) return v;
  const Eigen::Ref<Eigen::VectorXd> z = raw_values(*this, values);
  for (int i = 0; i < residual_dim(); ++i) {
    const RowSpec& row = rows_[i];
    if (row.kind == RowKind::kSoft) continue;
    const double viol = row_violation(row, z[i]);
    if (viol / row.scale > v.scaled) {
      v.scaled = viol / row.scale;
      v.own_units = viol;
      v.row = i;
      v.value = z[i];
    }
    if (!update) continue;
    const double mu = m->penalty;
    if (row.kind == RowKind::kEquality) {
      m->lower[i] += mu * (z[i] - row.lower) / row.scale;
    } else {
      // Infinite bounds give -inf here and clip to 0.
      m->lower[i] = std::max(0.0, m->lower[i] + mu * (row.lower - z[i]) / row.scale);
      m->upper[i] = std::max(0.0, m->upper[i] + mu * (z[i] - row.upper) / row.scale);
    }
  }
  return v;
}

double ConstrainedFactor::violation(const graph::Values& values) const {
  return num_constraints_ == 0 ? 0 : terms(values).violation;
}

ConstrainedFactor::Terms ConstrainedFactor::terms(const graph::Values& values) const {
  const Eigen::Ref<Eigen::VectorXd> z = raw_values(*this, values);
  Terms t;
  for (int i = 0; i < residual_dim(); ++i) {
    const RowSpec& row = rows_[i];
    if (row.kind == RowKind::kSoft) {
      t.soft_cost += 0.5 * std::pow(row.weight * (z[i] - row.lower), 2);
    } else {
      t.violation = std::max(t.violation, row_violation(row, z[i]));
    }
  }
  return t;
}

double ConstrainedFactor::scaled_violation(const graph::Values& values) const {
  if (num_constraints_ == 0) return 0;
  const Eigen::Ref<Eigen::VectorXd> z = raw_values(*this, values);
  double worst = 0;
  for (int i = 0; i < residual_dim(); ++i) {
    if (rows_[i].kind == RowKind::kSoft) continue;
    worst = std::max(worst, row_violation(rows_[i], z[i]) / rows_[i].scale);
  }
  return worst;
}

void ConstrainedFactor::declare_linear() {
  for (const RowSpec& row : rows_) {
    // A bound's hinge switches its row on and off with the variables.
    if (row.kind == RowKind::kBounds) {
      throw std::logic_error(name() + ": a factor with bound rows is not linear");
    }
  }
  set_linear();
}

}  // namespace kinograph::planning

#include "kinograph/graph/isam2.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <unordered_set>

#include "kinograph/graph/ordering.h"

namespace kinograph::graph {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}
}  // namespace

std::string to_string(ISAM2Status status) {
  switch (status) {
    case ISAM2Status::kOk:
      return "ok";
    case ISAM2Status::kSingular:
      return "singular";
    case ISAM2Status::kNonFinite:
      return "non_finite";
  }
  return "unknown";
}

ISAM2::ISAM2(ISAM2Options options)
    : options_(options), trust_radius_(options.trust_radius_initial) {
  if (options_.relinearize_skip < 1) {
    throw std::invalid_argument("ISAM2Options: relinearize_skip must be at least 1");
  }
  if (options_.relinearize_threshold < 0 || options_.wildfire_threshold < 0) {
    throw std::invalid_argument("ISAM2Options: thresholds must be non-negative");
  }
  if (options_.lambda_initial <= 0 || options_.lambda_factor <= 1 || options_.lambda_decrease < 1) {
    throw std::invalid_argument(
        "ISAM2Options: need lambda_initial > 0, lambda_factor > 1 and lambda_decrease >= 1");
  }
  if (options_.trust_radius_initial <= 0) {
    throw std::invalid_argument("ISAM2Options: trust_radius_initial must be positive");
  }
}

void ISAM2::sync_layout() {
  const int n = theta_.size();
  std::vector<int> dims(n), offsets(n);
  for (int s = 0; s < n; ++s) {
    dims[s] = theta_.dim(s);
    offsets[s] = theta_.offset(s);
  }
  tree_.set_layout(dims, offsets);
  const Eigen::Index old = delta_.size();
  const Eigen::Index total = theta_.total_dim();
  delta_.conservativeResize(total);
  delta_gn_.conservativeResize(total);
  delta_.tail(total - old).setZero();
  delta_gn_.tail(total - old).setZero();
  var_factors_.resize(n);
  stamp_.resize(n, 0);
}

// Up to this many active rows JᵀJ is formed coefficient by coefficient: the blocked product's
// packing costs more than the product for a collision factor's one or two rows.
constexpr int kLazyProductRows = 8;

bool ISAM2::evaluate_factor(int f, const Values& at, LinearizedFactor* out, double* error,
                            std::string* reason) {
  const Factor& factor = *graph_[f];
  const auto& slots = factor_slots_[f];
  const int nk = static_cast<int>(slots.size());
  ptrs_.resize(nk);
  for (int i = 0; i < nk; ++i) ptrs_[i] = at.vector().data() + at.offset(slots[i]);
  const int rows = factor.residual_dim();
  const int cols = factor.jacobian_cols();
  if (J_.rows() < rows || J_.cols() < cols) {
    J_.resize(std::max<Eigen::Index>(rows, J_.rows()), std::max<Eigen::Index>(cols, J_.cols()));
  }
  if (r_.size() < rows) r_.resize(rows);
  auto r = r_.head(rows);
  r.setZero();
  const auto non_finite = [&] {
    if (reason != nullptr) {
      *reason = "factor " + std::to_string(f) + " (" + factor.name() +
                ") returned a non-finite residual or Jacobian";
    }
    return false;
  };
  if (out == nullptr) {
    factor.whitened(ptrs_.data(), r, nullptr);
    *error = 0.5 * r.squaredNorm();
    return true;
  }
  LinearizedFactor& lf = *out;
  // The factor's free variables and their columns in J.
  free_vars_.clear();
  free_offsets_.clear();
  free_cols_.clear();
  for (int i = 0; i < nk; ++i) {
    if (at.is_fixed_slot(slots[i])) continue;
    free_vars_.push_back(slots[i]);
    free_offsets_.push_back(static_cast<int>(free_cols_.size()));
    for (int c = 0; c < factor.dims()[i]; ++c) free_cols_.push_back(factor.block_offsets()[i] + c);
  }
  const int off = static_cast<int>(free_cols_.size());
  const long version = factor.jacobian_version();
  if (options_.reuse_constant_jacobians && version >= 0 && lf.jacobian_version == version &&
      lf.vars == free_vars_) {
    // A linear factor whose Jacobian is unchanged since lf.H was formed: only r and Jᵀr are new.
    factor.whitened(ptrs_.data(), r, nullptr);
    if (!r.allFinite()) return non_finite();
    lf.error = 0.5 * r.squaredNorm();
    if (error != nullptr) *error = lf.error;
    lf.g.noalias() = lf.J.transpose() * r;
    lf.active = true;
    ++jacobians_kept_;
    return true;
  }
  Eigen::Ref<Eigen::MatrixXd> J = J_.topLeftCorner(rows, cols);
  factor.whitened(ptrs_.data(), r, &J);
  if (!r.allFinite() || !J.allFinite()) return non_finite();
  lf.error = 0.5 * r.squaredNorm();
  if (error != nullptr) *error = lf.error;
  lf.jacobian_version = options_.reuse_constant_jacobians ? version : -1;
  if (lf.jacobian_version >= 0) {
    lf.J.resize(rows, off);
    for (int c = 0; c < off; ++c) lf.J.col(c) = J.col(free_cols_[c]);
  } else {
    lf.J.resize(0, 0);
  }
  const int active = compact_nonzero_rows(J, r);
  lf.vars = free_vars_;
  lf.offsets = free_offsets_;
  const auto Ja = J.topRows(active);
  const auto ra = r.head(active);
  if (active == 0) {
    lf.H.setZero(off, off);
    lf.g.setZero(off);
  } else if (off == cols && active <= kLazyProductRows) {
    lf.H.noalias() = Ja.transpose().lazyProduct(Ja);
    lf.g.noalias() = Ja.transpose() * ra;
  } else if (off == cols) {
    lf.H.resize(off, off);
    jacobian_gram(Ja, lf.H, /*upper_only=*/false);
    lf.g.noalias() = Ja.transpose() * ra;
  } else {
    Eigen::MatrixXd Jf(active, off);
    for (int c = 0; c < off; ++c) Jf.col(c) = Ja.col(free_cols_[c]);
    lf.H.resize(off, off);
    jacobian_gram(Jf, lf.H, /*upper_only=*/false);
    lf.g.noalias() = Jf.transpose() * ra;
  }
  lf.active = true;
  return true;
}

bool ISAM2::linearize_factor(int f, std::string* reason) {
  // Reuse the linearization made when the error was evaluated at the estimate, if the factor's
  // variables have since been relinearized exactly there (θ = estimate: their δ is zero).
  if (at_estimate_ok_[f]) {
    bool at_estimate = true;
    for (int s : factor_slots_[f]) {
      if (!(delta_.segment(theta_.offset(s), theta_.dim(s)).array() == 0).all()) {
        at_estimate = false;
        break;
      }
    }
    if (at_estimate) {
      std::swap(linearized_[f], at_estimate_[f]);
      at_estimate_ok_[f] = 0;
      ++factors_reused_;
      return true;
    }
  }
  return evaluate_factor(f, theta_, &linearized_[f], nullptr, reason);
}

double ISAM2::factor_error_at_estimate(int f) {
  double error = 0;
  if (!options_.linearize_at_evaluation) {
    evaluate_factor(f, estimate_, nullptr, &error, nullptr);
    return error;
  }
  at_estimate_ok_[f] = evaluate_factor(f, estimate_, &at_estimate_[f], &error, nullptr) ? 1 : 0;
  return error;
}

void ISAM2::refresh_estimate(const std::vector<int>& changed_vars) {
  const bool evaluate = options_.safeguard || options_.step == ISAM2Step::kDogleg;
  ++factor_stamp_counter_;
  for (int s : changed_vars) {
    estimate_.at_slot(s) = theta_.at_slot(s) + delta_.segment(theta_.offset(s), theta_.dim(s));
  }
  if (!evaluate) return;
  for (int s : changed_vars) {
    for (int f : var_factors_[s]) {
      if (factor_stamp_[f] == factor_stamp_counter_) continue;
      factor_stamp_[f] = factor_stamp_counter_;
      factor_error_[f] = factor_error_at_estimate(f);
    }
  }
}

double ISAM2::total_error() const {
  double sum = 0;
  for (size_t f = 0; f < graph_.size(); ++f) {
    if (graph_[f]) sum += factor_error_[f];
  }
  return sum;
}

ISAM2Result ISAM2::update(const std::vector<FactorPtr>& new_factors,
                          const std::vector<size_t>& removed_factor_indices,
                          const Values& new_values, const ISAM2UpdateOptions& update_options) {
  const auto t_start = Clock::now();
  ISAM2Result res;
  const int kept_before = jacobians_kept_;
  const bool gauss_newton = options_.step == ISAM2Step::kGaussNewton;
  const bool evaluate = options_.safeguard || !gauss_newton;

  // --- Validate everything before touching any state.
  for (const Key& k : new_values.keys()) {
    if (theta_.contains(k)) {
      throw std::invalid_argument("ISAM2::update: variable " + k.to_string() + " already exists");
    }
  }
  for (size_t i = 0; i < new_factors.size(); ++i) {
    const auto& f = new_factors[i];
    if (!f)
      throw std::invalid_argument("ISAM2::update: new factor " + std::to_string(i) + " is null");
    for (size_t k = 0; k < f->keys().size(); ++k) {
      const Key key = f->keys()[k];
      int dim;
      if (theta_.contains(key)) {
        dim = theta_.dim(theta_.slot(key));
      } else if (new_values.contains(key)) {
        dim = new_values.dim(new_values.slot(key));
      } else {
        throw std::invalid_argument("ISAM2::update: factor " + f->name() + " uses " +
                                    key.to_string() + ", which has no value");
      }
      if (dim != f->dims()[k]) {
        throw std::invalid_argument(
            "ISAM2::update: factor " + f->name() + " expects " + key.to_string() +
            " of dimension " + std::to_string(f->dims()[k]) + ", value has " + std::to_string(dim));
      }
    }
  }
  {
    std::unordered_set<size_t> seen;
    for (size_t idx : removed_factor_indices) {
      if (idx >= graph_.size()) {
        throw std::out_of_range("ISAM2::update: no factor with index " + std::to_string(idx));
      }
      if (!graph_[idx] || !seen.insert(idx).second) {
        throw std::invalid_argument("ISAM2::update: factor " + std::to_string(idx) +
                                    " is already removed");
      }
    }
  }
  ++update_count_;

  // --- New variables.
  for (int s = 0; s < new_values.size(); ++s) {
    const Key k = new_values.key(s);
    theta_.insert(k, new_values.at_slot(s));
    estimate_.insert(k, new_values.at_slot(s));
    if (new_values.is_fixed_slot(s)) {
      theta_.set_fixed(k);
      estimate_.set_fixed(k);
    }
  }
  sync_layout();

  ++stamp_counter_;
  std::vector<int> marked;
  auto mark = [&](int s) {
    if (stamp_[s] != stamp_counter_ && !theta_.is_fixed_slot(s)) {
      stamp_[s] = stamp_counter_;
      marked.push_back(s);
    }
  };

  // --- Removed and added factors: their variables are touched.
  for (size_t idx : removed_factor_indices) {
    for (int s : factor_slots_[idx]) {
      mark(s);
      auto& list = var_factors_[s];
      list.erase(std::remove(list.begin(), list.end(), static_cast<int>(idx)), list.end());
    }
    linearized_[idx] = LinearizedFactor();
    at_estimate_[idx] = LinearizedFactor();
    at_estimate_ok_[idx] = 0;
    factor_error_[idx] = 0;
    factor_slots_[idx].clear();
    graph_.remove(idx);
  }
  std::vector<int> to_linearize;
  for (const auto& f : new_factors) {
    const int idx = static_cast<int>(graph_.add(f));
    res.new_factor_indices.push_back(idx);
    linearized_.resize(graph_.size());
    at_estimate_.resize(graph_.size());
    at_estimate_ok_.resize(graph_.size(), 0);
    factor_slots_.resize(graph_.size());
    factor_error_.resize(graph_.size(), 0);
    factor_stamp_.resize(graph_.size(), 0);
    for (const Key& k : f->keys()) {
      const int s = theta_.slot(k);
      factor_slots_[idx].push_back(s);
      var_factors_[s].push_back(idx);
      mark(s);
    }
    to_linearize.push_back(idx);
    if (evaluate) factor_error_[idx] = factor_error_at_estimate(idx);
  }
  const std::vector<int> touched = marked;
  if (evaluate) res.error_before = total_error();

  // --- Relinearization: θ_j ← θ_j + δ_j for variables that moved past the threshold; every
  // factor on them is relinearized and all their variables join the affected set.
  ++factor_stamp_counter_;
  for (int f : to_linearize) factor_stamp_[f] = factor_stamp_counter_;
  // A damped (LM) or trust-region-limited step is taken in full: its variables are
  // relinearized at the accepted point whatever the threshold, or the next update would
  // re-solve the same linear system and stall below the threshold.
  std::vector<char> took_step(theta_.size(), 0);
  for (int s : damped_vars_) took_step[s] = 1;
  const bool check =
      update_options.force_relinearize || (update_count_ - 1) % options_.relinearize_skip == 0;
  {
    double threshold = options_.relinearize_threshold;
    if (update_options.force_relinearize || (!gauss_newton && last_step_limited_)) threshold = 0;
    for (int s = 0; s < theta_.size(); ++s) {
      if (theta_.is_fixed_slot(s) || tree_.clique_of(s) < 0) continue;
      if (!check && !took_step[s]) continue;
      auto d = delta_.segment(theta_.offset(s), theta_.dim(s));
      if (d.cwiseAbs().maxCoeff() <= (took_step[s] ? 0.0 : threshold)) continue;
      ++res.variables_relinearized;
      theta_.at_slot(s) += d;
      d.setZero();
      delta_gn_.segment(theta_.offset(s), theta_.dim(s)).setZero();
      for (int f : var_factors_[s]) {
        if (factor_stamp_[f] != factor_stamp_counter_) {
          factor_stamp_[f] = factor_stamp_counter_;
          to_linearize.push_back(f);
        }
        for (int s2 : factor_slots_[f]) mark(s2);
      }
    }
  }
  for (int s : damped_vars_) mark(s);
  damped_vars_.clear();

  if (marked.empty() && !needs_full_) {
    res.error_after = res.error_before;
    res.error_evaluated = evaluate;
    res.lambda = lambda_;
    res.trust_radius = trust_radius_;
    res.total_s = seconds_since(t_start);
    return res;
  }

  // --- Which part of the tree to re-eliminate.
  const auto t_lin = Clock::now();
  bool full = needs_full_ || tree_.empty();
  std::vector<int> vars, held, orphans;
  int num_free = 0;
  for (int s = 0; s < theta_.size(); ++s) num_free += theta_.is_fixed_slot(s) ? 0 : 1;
  if (!full) {
    tree_.detach(marked, &vars, &held, &orphans);
    ++stamp_counter_;
    for (int s : vars) stamp_[s] = stamp_counter_;
    for (int s : marked) {
      if (stamp_[s] != stamp_counter_) {
        stamp_[s] = stamp_counter_;
        vars.push_back(s);
      }
    }
    if (vars.size() > options_.full_reelimination_fraction * num_free) full = true;
  }
  if (full) {
    tree_.clear();
    vars.clear();
    orphans.clear();
    for (int s = 0; s < theta_.size(); ++s) {
      if (!theta_.is_fixed_slot(s)) vars.push_back(s);
    }
    if (needs_full_) {  // after a failure, rebuild every linearization
      to_linearize.clear();
      for (size_t f = 0; f < graph_.size(); ++f) {
        if (graph_[f]) to_linearize.push_back(static_cast<int>(f));
      }
    }
  }
  res.full_reelimination = full;

  const int reused_before = factors_reused_;
  for (int f : to_linearize) {
    std::string reason;
    if (!linearize_factor(f, &reason)) {
      res.status = ISAM2Status::kNonFinite;
      res.reason = reason;
      tree_.clear();
      needs_full_ = true;
      res.total_s = seconds_since(t_start);
      return res;
    }
  }
  res.factors_linearized = static_cast<int>(to_linearize.size());
  res.factors_reused = factors_reused_ - reused_before;
  std::vector<int> factors;
  if (full) {
    for (size_t f = 0; f < graph_.size(); ++f) {
      if (graph_[f] && !linearized_[f].vars.empty()) factors.push_back(static_cast<int>(f));
    }
  } else {
    for (int f : held) {
      if (linearized_[f].active && !linearized_[f].vars.empty()) factors.push_back(f);
    }
    for (int idx : res.new_factor_indices) {
      if (!linearized_[idx].vars.empty()) factors.push_back(idx);
    }
  }
  res.linearize_s = seconds_since(t_lin);

  // --- Constrained ordering (touched variables last) and symbolic elimination.
  const auto t_elim = Clock::now();
  const int m = static_cast<int>(vars.size());
  std::vector<int> local(theta_.size(), -1);
  for (int i = 0; i < m; ++i) local[vars[i]] = i;
  std::vector<std::vector<int>> incidence;
  incidence.reserve(factors.size() + orphans.size());
  for (int f : factors) {
    auto& row = incidence.emplace_back();
    for (int s : linearized_[f].vars) row.push_back(local[s]);
  }
  for (int o : orphans) {
    auto& row = incidence.emplace_back();
    for (int s : tree_.clique(o).separator) row.push_back(local[s]);
  }
  std::vector<int> groups(m, 0);
  bool constrained = false;
  int touched_here = 0;
  for (int s : touched) touched_here += local[s] >= 0 ? 1 : 0;
  if (touched_here <= options_.constrain_touched_fraction * m) {
    for (int s : touched) {
      if (local[s] >= 0) {
        groups[local[s]] = 1;
        constrained = true;
      }
    }
  }
  for (const Key& k : update_options.constrained_last) {
    const int s = theta_.find(k);
    if (s >= 0 && local[s] >= 0) {
      groups[local[s]] = 1;
      constrained = true;
    }
  }
  const std::vector<int> order = compute_ordering(m, incidence, OrderingMethod::kColamd,
                                                  constrained ? groups : std::vector<int>{});
  const std::vector<int> new_cliques = tree_.build(vars, order, factors, linearized_, orphans);
  res.eliminate_s = seconds_since(t_elim);
  res.variables_reeliminated = m;
  res.cliques_reeliminated = static_cast<int>(new_cliques.size());

  // --- Numeric elimination and back-substitution; with the safeguard, damp and retry while
  // the error rises.
  Eigen::VectorXd diag_H, damping;
  double lambda = gauss_newton && options_.safeguard ? lambda_ : 0;
  std::vector<int> changed;
  bool accepted = true;
  for (;;) {
    ++res.trials;
    const Eigen::VectorXd* damping_ptr = nullptr;
    if (lambda > 0) {
      if (diag_H.size() == 0) {
        diag_H.setZero(theta_.total_dim());
        for (int s : vars) {
          for (int f : var_factors_[s]) {
            const LinearizedFactor& lf = linearized_[f];
            for (size_t i = 0; i < lf.vars.size(); ++i) {
              if (lf.vars[i] != s) continue;
              diag_H.segment(theta_.offset(s), theta_.dim(s)) +=
                  lf.H.diagonal().segment(lf.offsets[i], theta_.dim(s));
            }
          }
        }
        diag_H = diag_H.cwiseMax(options_.min_diagonal);
      }
      damping = lambda * diag_H;
      damping_ptr = &damping;
    }
    int bad_slot = -1;
    const auto t_factor = Clock::now();
    const bool factored = tree_.factorize(new_cliques, linearized_, damping_ptr, &bad_slot);
    res.eliminate_s += seconds_since(t_factor);
    if (!factored) {  // J is rank deficient: damping would only hide it
      res.status = ISAM2Status::kSingular;
      res.reason = "the information block of " + theta_.key(bad_slot).to_string() +
                   " is not positive definite (too few factors on it?)";
      tree_.clear();
      needs_full_ = true;
      res.total_s = seconds_since(t_start);
      return res;
    }
    const auto t_solve = Clock::now();
    changed.clear();
    res.cliques_solved = tree_.back_substitute(options_.wildfire_threshold, delta_gn_, &changed);
    if (gauss_newton) {
      for (int s : changed) {
        delta_.segment(theta_.offset(s), theta_.dim(s)) =
            delta_gn_.segment(theta_.offset(s), theta_.dim(s));
      }
      refresh_estimate(changed);
    }
    res.solve_s += seconds_since(t_solve);
    if (!gauss_newton || !evaluate) break;
    res.error_after = total_error();
    const double slack =
        options_.error_rise_tolerance * std::max(std::abs(res.error_before), 1e-300);
    if (res.error_after <= res.error_before + slack) break;
    if (!options_.safeguard) {
      accepted = false;
      break;
    }
    const double next = lambda == 0 ? options_.lambda_initial : lambda * options_.lambda_factor;
    if (next > options_.lambda_max) {
      accepted = false;
      break;
    }
    lambda = next;
  }
  needs_full_ = false;

  if (gauss_newton) {
    res.lambda = lambda;
    if (accepted) {
      lambda_ = lambda / options_.lambda_decrease;
      if (lambda_ < options_.lambda_min) lambda_ = 0;
    } else {
      lambda_ = lambda;
    }
    if (lambda > 0) damped_vars_ = vars;  // the tree holds a damped system for these
    res.error_increased = !accepted;
    res.error_evaluated = evaluate;
  } else {
    const auto t_dl = Clock::now();
    apply_dogleg(res, 0);
    res.solve_s += seconds_since(t_dl);
  }
  res.trust_radius = trust_radius_;
  tree_.clear_fresh();
  res.jacobians_kept = jacobians_kept_ - kept_before;
  res.total_s = seconds_since(t_start);
  spdlog::debug(
      "ISAM2 update {}: {} vars re-eliminated in {} cliques ({}), {} relinearized, {} cliques "
      "solved, error {:.6g} -> {:.6g}, lambda {:.3g}, {:.3f} ms",
      update_count_, res.variables_reeliminated, res.cliques_reeliminated,
      full ? "full" : "partial", res.variables_relinearized, res.cliques_solved, res.error_before,
      res.error_after, res.lambda, 1e3 * res.total_s);
  return res;
}

void ISAM2::apply_dogleg(ISAM2Result& res, double) {
  // Powell's dogleg on the linear model ½‖Rδ − d‖² held by the Bayes tree, about θ.
  double error_theta = 0;
  for (size_t f = 0; f < graph_.size(); ++f) {
    if (graph_[f]) error_theta += linearized_[f].error;
  }
  Eigen::VectorXd s(delta_.size());
  tree_.gradient(s);
  const double s2 = s.squaredNorm();
  const double Rs2 = tree_.r_norm_squared(s);
  const Eigen::VectorXd sd =
      Rs2 > 0 ? Eigen::VectorXd((s2 / Rs2) * s) : Eigen::VectorXd::Zero(s.size());
  const Eigen::VectorXd& gn = delta_gn_;
  const double gn_norm = gn.norm();
  const double sd_norm = sd.norm();
  const double model_zero = tree_.model_cost(Eigen::VectorXd::Zero(delta_.size()));
  std::vector<int> all;
  for (int v = 0; v < theta_.size(); ++v) {
    if (!theta_.is_fixed_slot(v)) all.push_back(v);
  }
  const double slack = options_.error_rise_tolerance * std::max(std::abs(res.error_before), 1e-300);
  Eigen::VectorXd step(delta_.size());
  for (int trial = 0;; ++trial) {
    ++res.trials;
    const double radius = trust_radius_;
    bool limited = true;
    if (gn_norm <= radius) {
      step = gn;
      limited = false;
    } else if (sd_norm >= radius) {
      step = (radius / sd_norm) * sd;
    } else {
      // τ in [0, 1] with ‖sd + τ(gn − sd)‖ = radius.
      const Eigen::VectorXd diff = gn - sd;
      const double a = diff.squaredNorm();
      const double b = 2 * sd.dot(diff);
      const double c = sd_norm * sd_norm - radius * radius;
      const double tau = (-b + std::sqrt(std::max(b * b - 4 * a * c, 0.0))) / (2 * a);
      step = sd + tau * diff;
    }
    delta_ = step;
    refresh_estimate(all);
    res.error_after = total_error();
    const double predicted = model_zero - tree_.model_cost(step);
    const double rho = predicted > 0 ? (error_theta - res.error_after) / predicted : 0;
    const double step_norm = step.norm();
    if (res.error_after <= res.error_before + slack) {
      if (rho > 0.75) {
        trust_radius_ = std::max(trust_radius_, 3 * step_norm);
      } else if (rho < 0.25) {
        trust_radius_ = std::max(0.5 * trust_radius_, options_.trust_radius_min);
      }
      last_step_limited_ = limited;
      break;
    }
    // The step made things worse: shrink below its length and try again.
    trust_radius_ = 0.25 * std::min(trust_radius_, step_norm);
    if (trust_radius_ < options_.trust_radius_min || trial + 1 >= options_.max_dogleg_trials ||
        step_norm == 0) {
      trust_radius_ = std::max(trust_radius_, options_.trust_radius_min);
      res.error_increased = true;
      last_step_limited_ = true;
      break;
    }
  }
  res.error_evaluated = true;
}

std::string ISAM2::check_invariants() const {
  std::vector<int> vars, factors;
  for (int s = 0; s < theta_.size(); ++s) {
    if (!theta_.is_fixed_slot(s)) vars.push_back(s);
  }
  for (size_t f = 0; f < graph_.size(); ++f) {
    if (!graph_[f]) continue;
    bool has_free = false;
    for (int s : factor_slots_[f]) has_free |= !theta_.is_fixed_slot(s);
    if (has_free) factors.push_back(static_cast<int>(f));
  }
  return tree_.check_invariants(vars, factors);
}

}  // namespace kinograph::graph

#include "kinograph/graph/isam2.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <unordered_set>
#include <utility>

#include "kinograph/graph/cancellation.h"
#include "kinograph/graph/ordering.h"
#include "kinograph/graph/stopwatch.h"
#include "kinograph/graph/worker_pool.h"

namespace kinograph::graph {

namespace {
using Clock = std::chrono::steady_clock;

// Slots of the variables that are not fixed, in slot order.
std::vector<int> free_slots(const Values& values) {
  std::vector<int> slots;
  for (int s = 0; s < values.size(); ++s) {
    if (!values.is_fixed_slot(s)) slots.push_back(s);
  }
  return slots;
}

// Up to this many active rows JᵀJ is formed coefficient by coefficient: the blocked product's
// packing costs more than the product for a collision factor's one or two rows.
constexpr int kLazyProductRows = 8;
// Fewer factors to evaluate than this, or fewer that may run on any thread, are evaluated on
// the caller's thread: sharing them out would cost about as much as it saves.
constexpr size_t kMinParallelFactors = 64;

// Powell's dogleg point at `radius` between the steepest-descent step `sd` and the Gauss–Newton
// step `gn` (norms given); returns whether the radius limited it.
bool dogleg_point(const Eigen::VectorXd& gn, double gn_norm, const Eigen::VectorXd& sd,
                  double sd_norm, double radius, Eigen::VectorXd& step) {
  if (gn_norm <= radius) {
    step = gn;
    return false;
  }
  if (sd_norm >= radius) {
    step = (radius / sd_norm) * sd;
    return true;
  }
  // τ in [0, 1] with ‖sd + τ(gn − sd)‖ = radius.
  const Eigen::VectorXd diff = gn - sd;
  const double a = diff.squaredNorm();
  const double b = 2 * sd.dot(diff);
  const double c = sd_norm * sd_norm - radius * radius;
  const double tau = (-b + std::sqrt(std::max(b * b - 4 * a * c, 0.0))) / (2 * a);
  step = sd + tau * diff;
  return true;
}
}  // namespace

/// What one update() works on, passed from step to step.
struct ISAM2::UpdateWork {
  bool gauss_newton = true;       // options_.step is Gauss–Newton
  bool evaluate = false;          // the nonlinear error is evaluated (safeguard or Dogleg)
  std::vector<int> marked;        // free variables whose cliques must be re-eliminated
  std::vector<int> touched;       // of those, the ones on removed or added factors
  std::vector<int> to_linearize;  // factors to linearize at θ
  std::vector<int> added;         // factors added by this update
  std::vector<int> unmarked_new;  // new factors without an active row, on variables one clique has
  std::vector<int> parked;        // of those, the ones held without re-elimination (sorted)
  bool full = false;              // rebuild the whole tree
  std::vector<int> vars;          // variables of the affected top
  std::vector<int> held;          // factors held by the detached cliques
  std::vector<int> orphans;       // roots of the subtrees below the affected top
  std::vector<int> factors;       // factors eliminated into the new cliques
  std::vector<int> new_cliques;   // cliques built by this update
  bool banded = false;            // solved whole by banded_ (no cliques built)
  std::vector<int> changed;       // variables back-substitution changed (last trial)
  double lambda = 0;              // damping of the last trial
  bool accepted = true;           // the last trial did not raise the error
  const ISAM2UpdateOptions* options = nullptr;  // of this update
};

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
  slot_dims_.resize(n);
  slot_offsets_.resize(n);
  for (int s = 0; s < n; ++s) {
    slot_dims_[s] = theta_.dim(s);
    slot_offsets_[s] = theta_.offset(s);
  }
  tree_.set_layout(slot_dims_, slot_offsets_);
  const Eigen::Index old = delta_.size();
  const Eigen::Index total = theta_.total_dim();
  delta_.conservativeResize(total);
  delta_gn_.conservativeResize(total);
  delta_.tail(total - old).setZero();
  delta_gn_.tail(total - old).setZero();
  var_factors_.resize(n);
  stamp_.resize(n, 0);
}

// ---------------------------------------------------------------------------------------------
// Linearizing one factor.

bool ISAM2::evaluate_factor(int f, const Values& at, LinearizedFactor* out, double* error,
                            FactorScratch& w) {
  const Factor& factor = *graph_[f];
  const auto& slots = factor_slots_[f];
  const int nk = static_cast<int>(slots.size());
  w.ptrs.resize(nk);
  for (int i = 0; i < nk; ++i) w.ptrs[i] = at.vector().data() + at.offset(slots[i]);
  const int rows = factor.residual_dim();
  const int cols = factor.jacobian_cols();
  if (w.J.rows() < rows || w.J.cols() < cols) {
    w.J.resize(std::max<Eigen::Index>(rows, w.J.rows()), std::max<Eigen::Index>(cols, w.J.cols()));
  }
  if (w.r.size() < rows) w.r.resize(rows);
  auto r = w.r.head(rows);
  r.setZero();
  if (out == nullptr) {
    factor.whitened(w.ptrs.data(), r, nullptr);
    *error = 0.5 * r.squaredNorm();
    return true;
  }
  collect_free_columns(factor, slots, at, w);
  const long version = factor.jacobian_version();
  const bool kept = options_.reuse_constant_jacobians && version >= 0 &&
                    out->jacobian_version == version && out->vars == w.free_vars;
  return kept ? relinearize_kept_jacobian(factor, *out, error, w)
              : linearize_fresh(factor, *out, error, w);
}

std::string ISAM2::non_finite_reason(int f) const {
  return "factor " + std::to_string(f) + " (" + graph_[f]->name() +
         ") returned a non-finite residual or Jacobian";
}

// The factor's free variables (w.free_vars), their first columns among the free ones
// (w.free_offsets) and the stacked Jacobian's column of each free column (w.free_cols).
void ISAM2::collect_free_columns(const Factor& factor, const std::vector<int>& slots,
                                 const Values& at, FactorScratch& w) {
  w.free_vars.clear();
  w.free_offsets.clear();
  w.free_cols.clear();
  for (size_t i = 0; i < slots.size(); ++i) {
    if (at.is_fixed_slot(slots[i])) continue;
    w.free_vars.push_back(slots[i]);
    w.free_offsets.push_back(static_cast<int>(w.free_cols.size()));
    for (int c = 0; c < factor.dims()[i]; ++c) w.free_cols.push_back(factor.block_offsets()[i] + c);
  }
}

// A linear factor whose Jacobian is unchanged since lf.H was formed: only r and Jᵀr are new.
bool ISAM2::relinearize_kept_jacobian(const Factor& factor, LinearizedFactor& lf, double* error,
                                      FactorScratch& w) {
  auto r = w.r.head(factor.residual_dim());
  factor.whitened(w.ptrs.data(), r, nullptr);
  if (!r.allFinite()) return false;
  lf.error = 0.5 * r.squaredNorm();
  if (error != nullptr) *error = lf.error;
  if (!lf.zero) lf.g.noalias() = lf.J.transpose() * r;  // zero: J has no nonzero row
  lf.active = true;
  ++w.jacobians_kept;
  return true;
}

// Residual, Jacobian and JᵀJ, Jᵀr over the free columns; a linear factor also keeps its
// free-column Jacobian so the next linearization can skip JᵀJ.
bool ISAM2::linearize_fresh(const Factor& factor, LinearizedFactor& lf, double* error,
                            FactorScratch& w) {
  const int rows = factor.residual_dim();
  auto r = w.r.head(rows);
  Eigen::Ref<Eigen::MatrixXd> J = w.J.topLeftCorner(rows, factor.jacobian_cols());
  const long version = options_.reuse_constant_jacobians ? factor.jacobian_version() : -1;
  // A kept linear factor's J must be whole.
  RowSupport* support = version >= 0 ? nullptr : &w.support;
  factor.whitened(w.ptrs.data(), r, &J, support);
  if (!r.allFinite() || (version >= 0 && !all_finite(J))) return false;
  const double factor_error = 0.5 * r.squaredNorm();  // before the compaction reorders r
  bool finite = true;
  if (version >= 0) {  // whole and finite: its compaction below cannot fail
    const int off = static_cast<int>(w.free_cols.size());
    lf.J.resize(rows, off);
    for (int c = 0; c < off; ++c) lf.J.col(c) = J.col(w.free_cols[c]);
  }
  const int active = compact_nonzero_rows(J, r, &finite, support);
  if (!finite) return false;
  if (version < 0) lf.J.resize(0, 0);
  lf.jacobian_version = version;
  lf.error = factor_error;
  if (error != nullptr) *error = lf.error;
  lf.vars = w.free_vars;
  lf.offsets = w.free_offsets;
  form_normal_equations(J, active, lf, w);
  lf.active = true;
  return true;
}

// lf.H = JᵀJ and lf.g = Jᵀr over the first `active` rows (those not all zero) and the free
// columns; r is the residual in w.r. Without an active row the factor is only marked zero: in a
// planning graph most inequality rows hold, and their factors need no work in the cliques.
void ISAM2::form_normal_equations(Eigen::Ref<Eigen::MatrixXd> J, int active, LinearizedFactor& lf,
                                  const FactorScratch& w) {
  lf.zero = active == 0;
  if (lf.zero) return;
  auto r = w.r.head(J.rows());
  const int off = static_cast<int>(w.free_cols.size());
  const auto Ja = J.topRows(active);
  const auto ra = r.head(active);
  if (off == J.cols() && active <= kLazyProductRows) {
    lf.H.noalias() = Ja.transpose().lazyProduct(Ja);
    lf.g.noalias() = Ja.transpose() * ra;
  } else if (off == J.cols()) {
    lf.H.resize(off, off);
    jacobian_gram(Ja, lf.H, /*upper_only=*/false);
    lf.g.noalias() = Ja.transpose() * ra;
  } else {
    Eigen::MatrixXd Jf(active, off);
    for (int c = 0; c < off; ++c) Jf.col(c) = Ja.col(w.free_cols[c]);
    lf.H.resize(off, off);
    jacobian_gram(Jf, lf.H, /*upper_only=*/false);
    lf.g.noalias() = Jf.transpose() * ra;
  }
}

bool ISAM2::linearize_factor(int f, FactorScratch& w) {
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
      ++w.reused;
      return true;
    }
  }
  return evaluate_factor(f, theta_, &linearized_[f], nullptr, w);
}

double ISAM2::factor_error_at_estimate(int f, FactorScratch& w) {
  double error = 0;
  if (!options_.linearize_at_evaluation) {
    evaluate_factor(f, estimate_, nullptr, &error, w);
    return error;
  }
  at_estimate_ok_[f] = evaluate_factor(f, estimate_, &at_estimate_[f], &error, w) ? 1 : 0;
  return error;
}

template <class F>
void ISAM2::for_each_factor(const std::vector<int>& factors, ShareOutChoice& choice, F&& one) {
  any_worker_.clear();
  caller_only_.clear();
  if (options_.threads > 1 && factors.size() >= kMinParallelFactors) {
    for (int f : factors) (graph_[f]->parallel_safe() ? any_worker_ : caller_only_).push_back(f);
  }
  if (any_worker_.size() < kMinParallelFactors) {
    for (int f : factors) one(f, scratch_[0]);
  } else {
    const auto t0 = Clock::now();
    const bool share = choice.share();
    if (share) {
      auto call = [&](int f, int worker) { one(f, scratch_[static_cast<size_t>(worker)]); };
      share_out(options_.threads, caller_only_, any_worker_, call);
    } else {
      for (int f : factors) one(f, scratch_[0]);
    }
    choice.record(share, factors.size(), seconds_since(t0));
  }
  count_scratch();
}

void ISAM2::count_scratch() {
  for (FactorScratch& w : scratch_) {
    factors_reused_ += std::exchange(w.reused, 0);
    jacobians_kept_ += std::exchange(w.jacobians_kept, 0);
  }
}

void ISAM2::refresh_estimate(const std::vector<int>& changed_vars) {
  const bool evaluate = options_.safeguard || options_.step == ISAM2Step::kDogleg;
  ++factor_stamp_counter_;
  for (int s : changed_vars) {
    estimate_.at_slot(s) = theta_.at_slot(s) + delta_.segment(theta_.offset(s), theta_.dim(s));
  }
  if (!evaluate) return;
  refreshed_.clear();
  for (int s : changed_vars) {
    for (int f : var_factors_[s]) {
      if (factor_stamp_[f] == factor_stamp_counter_) continue;
      factor_stamp_[f] = factor_stamp_counter_;
      refreshed_.push_back(f);
    }
  }
  for_each_factor(refreshed_, refresh_choice_, [this](int f, FactorScratch& w) {
    factor_error_[f] = factor_error_at_estimate(f, w);
  });
}

double ISAM2::total_error() const {
  double sum = 0;
  for (size_t f = 0; f < graph_.size(); ++f) {
    if (graph_[f]) sum += factor_error_[f];
  }
  return sum;
}

// ---------------------------------------------------------------------------------------------
// update() and its steps, in order.

ISAM2Result ISAM2::update(const std::vector<FactorPtr>& new_factors,
                          const std::vector<size_t>& removed_factor_indices,
                          const Values& new_values, const ISAM2UpdateOptions& update_options) {
  throw_if_cancelled();  // before anything of this update is applied
  const auto t_start = Clock::now();
  ISAM2Result res;
  const int kept_before = jacobians_kept_;
  validate_update(new_factors, removed_factor_indices, new_values);
  ++update_count_;
  UpdateWork work;
  work.gauss_newton = options_.step == ISAM2Step::kGaussNewton;
  work.evaluate = options_.safeguard || !work.gauss_newton;
  work.options = &update_options;

  add_variables(new_values);
  ++stamp_counter_;  // a new marking: mark() stamps variables with this counter
  remove_factors(removed_factor_indices, work);
  add_factors(new_factors, work, res);
  if (!linearize_new_factors(work, res)) {
    res.total_s = seconds_since(t_start);
    return res;
  }
  work.touched = work.marked;
  if (work.evaluate) res.error_before = total_error();
  relinearize(update_options, work, res);
  const bool reeliminate = !work.marked.empty() || needs_full_;
  if (!reeliminate) park_new_factors(work);
  if (!reeliminate && !prepared_) {  // nothing to re-eliminate, no step left to take
    report_unchanged(work, res);
    res.total_s = seconds_since(t_start);
    return res;
  }

  // Without a change only the prepared tree's step is taken.
  if ((reeliminate && !detach_and_linearize(work, res, /*allow_banded=*/true)) ||
      !eliminate_and_solve(work, res)) {
    res.total_s = seconds_since(t_start);
    return res;
  }
  needs_full_ = false;

  if (work.gauss_newton) {
    carry_damping(work, res);
  } else {
    const auto t_dl = Clock::now();
    apply_dogleg(res);
    res.solve_s += seconds_since(t_dl);
  }
  res.trust_radius = trust_radius_;
  tree_.clear_fresh();
  prepared_ = false;
  count_scratch();
  res.jacobians_kept = jacobians_kept_ - kept_before;
  res.total_s = seconds_since(t_start);
  spdlog::debug(
      "ISAM2 update {}: {} vars re-eliminated in {} cliques ({}), {} relinearized, {} cliques "
      "solved, error {:.6g} -> {:.6g}, lambda {:.3g}, {:.3f} ms (linearize {:.3f}, eliminate "
      "{:.3f}, solve {:.3f})",
      update_count_, res.variables_reeliminated, res.cliques_reeliminated,
      work.full ? "full" : "partial", res.variables_relinearized, res.cliques_solved,
      res.error_before, res.error_after, res.lambda, 1e3 * res.total_s, 1e3 * res.linearize_s,
      1e3 * res.eliminate_s, 1e3 * res.solve_s);
  return res;
}

ISAM2Result ISAM2::relinearize_at_estimate(const std::vector<Key>& last) {
  const auto t_start = Clock::now();
  ISAM2Result res;
  UpdateWork work;
  work.gauss_newton = options_.step == ISAM2Step::kGaussNewton;
  work.evaluate = false;
  ISAM2UpdateOptions all;
  all.force_relinearize = true;
  all.constrained_last = last;
  work.options = &all;
  ++stamp_counter_;
  relinearize(all, work, res);
  if (work.marked.empty() && !needs_full_ && !tree_deferred_) {
    report_unchanged(work, res);
    res.total_s = seconds_since(t_start);
    return res;
  }
  if (!detach_and_linearize(work, res, /*allow_banded=*/false)) {
    res.total_s = seconds_since(t_start);
    return res;
  }
  // Damped as the next update's first trial would be: that trial then re-eliminates only its
  // own top and takes the same step as if it had re-eliminated everything.
  Eigen::VectorXd damping;
  if (work.gauss_newton && options_.safeguard && lambda_ > 0) {
    damping = lambda_ * damping_diagonal(work.vars);
    prepared_damped_ = work.vars;
  }
  int bad_slot = -1;
  const auto t_factor = Clock::now();
  const bool factored = tree_.factorize(work.new_cliques, linearized_,
                                        damping.size() > 0 ? &damping : nullptr, &bad_slot);
  res.eliminate_s += seconds_since(t_factor);
  res.trials = 1;
  if (!factored) {
    fail_singular(res, bad_slot);
    res.total_s = seconds_since(t_start);
    return res;
  }
  // The new cliques' solution is not taken: δ stays 0 (θ is the estimate). They stay fresh, so
  // the next update back-substitutes every one of them and takes the step it skipped here.
  needs_full_ = false;
  prepared_ = true;
  count_scratch();
  res.lambda = lambda_;
  res.trust_radius = trust_radius_;
  res.total_s = seconds_since(t_start);
  return res;
}

void ISAM2::rename_variables(const std::function<Key(Key)>& rename) {
  Values theta = theta_, estimate = estimate_;
  theta.rename(rename);  // throws before anything changed when two keys merge
  estimate.rename(rename);
  // A factor's keys are distinct and map to distinct keys, so renaming them cannot throw.
  for (size_t i = 0; i < graph_.size(); ++i) {
    if (graph_[i]) graph_[i]->rename_keys(rename);
  }
  theta_ = std::move(theta);
  estimate_ = std::move(estimate);
}

// Throws for inconsistent input before update() changes any state.
void ISAM2::validate_update(const std::vector<FactorPtr>& new_factors,
                            const std::vector<size_t>& removed_factor_indices,
                            const Values& new_values) const {
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

// New variables enter θ and the estimate at their initial values (δ = 0).
void ISAM2::add_variables(const Values& new_values) {
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
}

// Marks a free variable once per update: its clique and the path to the root are re-eliminated.
void ISAM2::mark(int slot, UpdateWork& work) {
  if (stamp_[slot] != stamp_counter_ && !theta_.is_fixed_slot(slot)) {
    stamp_[slot] = stamp_counter_;
    work.marked.push_back(slot);
  }
}

// Removed factors leave their slot empty; their variables are touched, unless the factor added
// nothing to its clique (no active row at θ): then it only leaves the clique's list.
void ISAM2::remove_factors(const std::vector<size_t>& removed_factor_indices, UpdateWork& work) {
  for (size_t idx : removed_factor_indices) {
    const LinearizedFactor& lf = linearized_[idx];
    const bool added_nothing = lf.active && lf.zero;
    if (added_nothing) tree_.release(static_cast<int>(idx), lf.vars);
    for (int s : factor_slots_[idx]) {
      if (!added_nothing) mark(s, work);
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
}

// Added factors are registered (and their error at the estimate taken, to judge the step);
// linearize_new_factors decides which of their variables are touched.
void ISAM2::add_factors(const std::vector<FactorPtr>& new_factors, UpdateWork& work,
                        ISAM2Result& res) {
  for (const auto& f : new_factors) {
    const int idx = static_cast<int>(graph_.add(f));
    res.new_factor_indices.push_back(idx);
    work.added.push_back(idx);
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
    }
    if (work.evaluate) factor_error_[idx] = factor_error_at_estimate(idx, scratch_[0]);
  }
}

// New factors are linearized at θ here. One with an active row, or on variables no clique has
// together, touches its variables; one without (most collision pairs of a planning graph are
// clear) changes no clique's numbers and is only held by a clique (park_new_factors).
bool ISAM2::linearize_new_factors(UpdateWork& work, ISAM2Result& res) {
  if (needs_full_) {  // the rebuild linearizes every factor
    for (int idx : work.added) {
      for (int s : factor_slots_[idx]) mark(s, work);
    }
    return true;
  }
  if (!linearize_factors(work.added, res)) return false;
  for (int idx : work.added) {
    const LinearizedFactor& lf = linearized_[idx];
    if (lf.zero && tree_.holder(lf.vars) >= 0) {
      work.unmarked_new.push_back(idx);
    } else {
      for (int s : factor_slots_[idx]) mark(s, work);
    }
  }
  return true;
}

// The unmarked new factors go to a clique that has their variables and was not detached;
// the others (their clique was) are eliminated with the affected top, which has all their
// variables: a detached clique's separator lies in its detached ancestors.
void ISAM2::park_new_factors(UpdateWork& work) {
  for (int idx : work.unmarked_new) {
    if (tree_.hold(idx, linearized_[idx].vars)) work.parked.push_back(idx);
  }
  std::sort(work.parked.begin(), work.parked.end());
}

// Variables whose δ moved past the threshold (checked every relinearize_skip-th update), and
// every variable of the last damped step whatever its δ: a damped (LM) or trust-region-limited
// step is taken in full, or the next update would re-solve the same system and stall.
std::vector<int> ISAM2::variables_to_relinearize(const ISAM2UpdateOptions& update_options) const {
  std::vector<char> took_step(theta_.size(), 0);
  for (int s : damped_vars_) took_step[s] = 1;
  const bool check =
      update_options.force_relinearize || (update_count_ - 1) % options_.relinearize_skip == 0;
  double threshold = options_.relinearize_threshold;
  if (update_options.force_relinearize ||
      (options_.step != ISAM2Step::kGaussNewton && last_step_limited_)) {
    threshold = 0;
  }
  std::vector<int> chosen;
  for (int s = 0; s < theta_.size(); ++s) {
    // A variable not yet eliminated has no δ; a deferred tree holds none, the banded step all.
    if (theta_.is_fixed_slot(s) || (!tree_deferred_ && tree_.clique_of(s) < 0)) continue;
    if (!check && !took_step[s]) continue;
    const auto d = delta_.segment(theta_.offset(s), theta_.dim(s));
    if (d.cwiseAbs().maxCoeff() <= (took_step[s] ? 0.0 : threshold)) continue;
    chosen.push_back(s);
  }
  return chosen;
}

// θ_j ← θ_j + δ_j for the chosen variables; every factor on them is queued for linearization
// and all their variables (and those of the last damped step) are marked.
void ISAM2::relinearize(const ISAM2UpdateOptions& update_options, UpdateWork& work,
                        ISAM2Result& res) {
  ++factor_stamp_counter_;
  for (int f : work.to_linearize) factor_stamp_[f] = factor_stamp_counter_;
  const std::vector<int> chosen = variables_to_relinearize(update_options);
  res.variables_relinearized = static_cast<int>(chosen.size());
  for (int s : chosen) {
    auto d = delta_.segment(theta_.offset(s), theta_.dim(s));
    theta_.at_slot(s) += d;
    d.setZero();
    delta_gn_.segment(theta_.offset(s), theta_.dim(s)).setZero();
    for (int f : var_factors_[s]) {
      if (factor_stamp_[f] != factor_stamp_counter_) {
        factor_stamp_[f] = factor_stamp_counter_;
        work.to_linearize.push_back(f);
      }
      for (int s2 : factor_slots_[f]) mark(s2, work);
    }
  }
  for (int s : damped_vars_) mark(s, work);
  damped_vars_.clear();
}

// An update that changed no factor on a free variable and relinearized nothing: the estimate
// stands, with the carried λ and trust radius.
void ISAM2::report_unchanged(const UpdateWork& work, ISAM2Result& res) const {
  res.error_after = res.error_before;
  res.error_evaluated = work.evaluate;
  res.lambda = lambda_;
  res.trust_radius = trust_radius_;
}

// The part of the tree to re-eliminate: the cliques of the marked variables and their
// ancestors (detached with their factors, leaving orphaned subtrees), or the whole tree when
// that part is most of it or the tree must be rebuilt after a failure.
void ISAM2::find_affected_top(UpdateWork& work) {
  work.full = needs_full_ || tree_.empty();
  const int num_free = static_cast<int>(free_slots(theta_).size());
  if (!work.full) {
    tree_.detach(work.marked, &work.vars, &work.held, &work.orphans);
    ++stamp_counter_;
    for (int s : work.vars) stamp_[s] = stamp_counter_;
    for (int s : work.marked) {  // marked variables new to the tree
      if (stamp_[s] != stamp_counter_) {
        stamp_[s] = stamp_counter_;
        work.vars.push_back(s);
      }
    }
    if (work.vars.size() > options_.full_reelimination_fraction * num_free) work.full = true;
  }
  if (work.full) {
    tree_.clear();
    work.vars = free_slots(theta_);
    work.orphans.clear();
    if (needs_full_) work.to_linearize = active_factors();  // rebuild every linearization
  }
}

std::vector<int> ISAM2::active_factors() const {
  std::vector<int> factors;
  for (size_t f = 0; f < graph_.size(); ++f) {
    if (graph_[f]) factors.push_back(static_cast<int>(f));
  }
  return factors;
}

// Linearizes `factors` at θ; false (the result says which factor) if one is not finite.
bool ISAM2::linearize_factors(const std::vector<int>& factors, ISAM2Result& res) {
  const int reused_before = factors_reused_;
  linearized_ok_.resize(graph_.size());
  for_each_factor(factors, linearize_choice_, [this](int f, FactorScratch& w) {
    linearized_ok_[f] = linearize_factor(f, w);
  });
  for (int f : factors) {
    if (!linearized_ok_[f]) {
      fail(res, ISAM2Status::kNonFinite, non_finite_reason(f));
      return false;
    }
  }
  res.factors_linearized += static_cast<int>(factors.size());
  res.factors_reused += factors_reused_ - reused_before;
  for (int f : factors) res.factors_zero += linearized_[f].zero ? 1 : 0;
  return true;
}

// A failed update leaves no usable tree: the next one rebuilds it and every linearization.
void ISAM2::fail(ISAM2Result& res, ISAM2Status status, std::string reason) {
  res.status = status;
  res.reason = std::move(reason);
  tree_.clear();
  tree_deferred_ = false;
  needs_full_ = true;
  prepared_ = false;
  prepared_damped_.clear();
}

void ISAM2::fail_singular(ISAM2Result& res, int slot) {
  fail(res, ISAM2Status::kSingular,
       "the information block of " + theta_.key(slot).to_string() +
           " is not positive definite (too few factors on it?)");
}

// The affected top detached, its factors linearized and its new cliques built (symbolically),
// or for a banded update the whole system assembled; false (the result says which factor) if a
// factor is not finite.
bool ISAM2::detach_and_linearize(UpdateWork& work, ISAM2Result& res, bool allow_banded) {
  const auto t_lin = Clock::now();
  find_affected_top(work);
  res.full_reelimination = work.full;
  if (!work.full) park_new_factors(work);
  if (!linearize_factors(work.to_linearize, res)) return false;
  work.factors = factors_to_eliminate(work);
  res.linearize_s = seconds_since(t_lin);
  const auto t_elim = Clock::now();
  work.banded = allow_banded && solve_banded(work, res.variables_relinearized);
  tree_deferred_ = work.banded;
  if (work.banded) {
    banded_.assemble(linearized_, work.factors);
    res.eliminate_s = seconds_since(t_elim);
    res.variables_reeliminated = static_cast<int>(work.vars.size());
    return true;
  }
  build_affected_top(*work.options, work, res);
  return true;
}

// Whether this update's step comes from the whole system (banded_full_updates): a Gauss–Newton
// update that relinearizes most variables (it re-eliminates the whole tree however small its
// own change) on a graph whose Hessian is banded in slot order.
bool ISAM2::solve_banded(const UpdateWork& work, int relinearized) {
  const double most = options_.full_reelimination_fraction * static_cast<double>(work.vars.size());
  if (!options_.banded_full_updates || !work.gauss_newton || !work.full || relinearized <= most) {
    return false;
  }
  return banded_.prepare(work.vars, slot_dims_, linearized_, work.factors);
}

// Factors eliminated into the new cliques (those with a free variable): every one after a full
// re-elimination, else those the detached cliques held and the new ones not parked.
std::vector<int> ISAM2::factors_to_eliminate(const UpdateWork& work) const {
  std::vector<int> factors;
  if (work.full) {
    for (size_t f = 0; f < graph_.size(); ++f) {
      if (graph_[f] && !linearized_[f].vars.empty()) factors.push_back(static_cast<int>(f));
    }
    return factors;
  }
  for (int f : work.held) {
    if (linearized_[f].active && !linearized_[f].vars.empty()) factors.push_back(f);
  }
  for (int idx : work.added) {
    if (linearized_[idx].vars.empty() ||
        std::binary_search(work.parked.begin(), work.parked.end(), idx)) {
      continue;
    }
    factors.push_back(idx);
  }
  return factors;
}

// Constrained ordering of the affected top and symbolic elimination into new cliques.
void ISAM2::build_affected_top(const ISAM2UpdateOptions& update_options, UpdateWork& work,
                               ISAM2Result& res) {
  const auto t_elim = Clock::now();
  const int m = static_cast<int>(work.vars.size());
  std::vector<int> local(theta_.size(), -1);  // slot → position in work.vars
  for (int i = 0; i < m; ++i) local[work.vars[i]] = i;
  const std::vector<std::vector<int>> incidence = elimination_incidence(work, local);
  const std::vector<int> groups = ordering_groups(update_options, work, local);
  const std::vector<int> order = compute_ordering(m, incidence, OrderingMethod::kColamd, groups);
  work.new_cliques = tree_.build(work.vars, order, work.factors, linearized_, work.orphans);
  res.eliminate_s = seconds_since(t_elim);
  res.variables_reeliminated = m;
  res.cliques_reeliminated = static_cast<int>(work.new_cliques.size());
}

// Rows of the affected top's variables (positions in work.vars): one per factor and one per
// orphan's separator (its cached marginal factor).
std::vector<std::vector<int>> ISAM2::elimination_incidence(const UpdateWork& work,
                                                           const std::vector<int>& local) const {
  std::vector<std::vector<int>> incidence;
  incidence.reserve(work.factors.size() + work.orphans.size());
  for (int f : work.factors) {
    auto& row = incidence.emplace_back();
    for (int s : linearized_[f].vars) row.push_back(local[s]);
  }
  for (int o : work.orphans) {
    auto& row = incidence.emplace_back();
    for (int s : tree_.clique(o).separator) row.push_back(local[s]);
  }
  return incidence;
}

// Ordering groups of the affected top's variables: 1 (eliminated last) for the constrained_last
// keys and, while they are few enough, the touched variables; empty when none is constrained.
std::vector<int> ISAM2::ordering_groups(const ISAM2UpdateOptions& update_options,
                                        const UpdateWork& work,
                                        const std::vector<int>& local) const {
  const int m = static_cast<int>(work.vars.size());
  std::vector<int> groups(m, 0);
  bool constrained = false;
  const auto last = [&](int s) {
    if (s >= 0 && local[s] >= 0) {
      groups[local[s]] = 1;
      constrained = true;
    }
  };
  int touched_here = 0;
  for (int s : work.touched) touched_here += local[s] >= 0 ? 1 : 0;
  if (touched_here <= options_.constrain_touched_fraction * m) {
    for (int s : work.touched) last(s);
  }
  for (const Key& k : update_options.constrained_last) last(theta_.find(k));
  return constrained ? groups : std::vector<int>{};
}

// Numeric elimination and back-substitution; with the safeguard, Gauss–Newton retries with
// Marquardt damping (λ growing) while the error rises. False when a clique is singular.
bool ISAM2::eliminate_and_solve(UpdateWork& work, ISAM2Result& res) {
  Eigen::VectorXd diag_H, damping;
  work.lambda = work.gauss_newton && options_.safeguard ? lambda_ : 0;
  work.accepted = true;
  for (;;) {
    ++res.trials;
    const Eigen::VectorXd* damping_ptr = nullptr;
    if (work.lambda > 0) {
      if (diag_H.size() == 0) diag_H = damping_diagonal(work.vars);
      damping = work.lambda * diag_H;
      damping_ptr = &damping;
    }
    if (!factorize_and_solve(work, damping_ptr, res)) return false;
    // Past here the error is evaluated with Gauss–Newton only with the safeguard on.
    if (!work.gauss_newton || !work.evaluate) return true;
    res.error_after = total_error();
    const double slack =
        options_.error_rise_tolerance * std::max(std::abs(res.error_before), 1e-300);
    if (res.error_after <= res.error_before + slack) return true;
    const double next =
        work.lambda == 0 ? options_.lambda_initial : work.lambda * options_.lambda_factor;
    if (next > options_.lambda_max) {
      work.accepted = false;
      return true;
    }
    work.lambda = next;
    // A prepared tree's step moved every variable: damping only this update's top would not
    // shorten it.
    if (prepared_ && !work.full) {
      reeliminate_all(work, res);
      diag_H.resize(0);
    }
  }
}

// Widens the affected top to the whole tree (the linearizations stay).
void ISAM2::reeliminate_all(UpdateWork& work, ISAM2Result& res) {
  prepared_ = false;
  prepared_damped_.clear();
  work.full = true;
  res.full_reelimination = true;
  tree_.clear();
  work.vars = free_slots(theta_);
  work.orphans.clear();
  work.factors = factors_to_eliminate(work);
  build_affected_top(*work.options, work, res);
}

// diag(H) of the affected top's variables, floored at min_diagonal (zero elsewhere).
Eigen::VectorXd ISAM2::damping_diagonal(const std::vector<int>& vars) const {
  Eigen::VectorXd diag_H;
  diag_H.setZero(theta_.total_dim());
  for (int s : vars) {
    for (int f : var_factors_[s]) {
      const LinearizedFactor& lf = linearized_[f];
      if (lf.zero) continue;
      for (size_t i = 0; i < lf.vars.size(); ++i) {
        if (lf.vars[i] != s) continue;
        diag_H.segment(theta_.offset(s), theta_.dim(s)) +=
            lf.H.diagonal().segment(lf.offsets[i], theta_.dim(s));
      }
    }
  }
  return diag_H.cwiseMax(options_.min_diagonal);
}

// One trial: factorizes the new cliques (damped if given) and back-substitutes δ, or solves the
// banded system; Gauss–Newton takes it as the step. False (the result says where) when the
// system is not positive definite.
bool ISAM2::factorize_and_solve(UpdateWork& work, const Eigen::VectorXd* damping,
                                ISAM2Result& res) {
  int bad_slot = -1;
  const auto t_factor = Clock::now();
  const bool factored = work.banded
                            ? banded_.solve(damping, slot_offsets_, delta_gn_, &bad_slot)
                            : tree_.factorize(work.new_cliques, linearized_, damping, &bad_slot);
  res.eliminate_s += seconds_since(t_factor);
  if (!factored) {  // J is rank deficient: damping would only hide it
    fail_singular(res, bad_slot);
    return false;
  }
  const auto t_solve = Clock::now();
  if (work.banded) {
    work.changed = work.vars;  // the banded solve gave every variable's step
    res.cliques_solved = 0;
  } else {
    work.changed.clear();
    res.cliques_solved =
        tree_.back_substitute(options_.wildfire_threshold, delta_gn_, &work.changed);
  }
  if (work.gauss_newton) {
    for (int s : work.changed) {
      delta_.segment(theta_.offset(s), theta_.dim(s)) =
          delta_gn_.segment(theta_.offset(s), theta_.dim(s));
    }
    refresh_estimate(work.changed);
  }
  res.solve_s += seconds_since(t_solve);
  return true;
}

// After a Gauss–Newton update: λ for the next one (shrunk after an accepted trial, kept after a
// failed search) and the damped variables, whose step is taken in full at the next update.
void ISAM2::carry_damping(const UpdateWork& work, ISAM2Result& res) {
  res.lambda = work.lambda;
  if (work.accepted) {
    lambda_ = work.lambda / options_.lambda_decrease;
    if (lambda_ < options_.lambda_min) lambda_ = 0;
  } else {
    lambda_ = work.lambda;
  }
  // The tree holds a damped system for these (a prepared tree's too, below this update's top).
  if (work.lambda > 0) damped_vars_ = work.vars;
  if (!work.full) damped_vars_.insert(damped_vars_.end(), prepared_damped_.begin(),
                                      prepared_damped_.end());
  prepared_damped_.clear();
  res.error_increased = !work.accepted;
  res.error_evaluated = work.evaluate;
}

// Powell's dogleg on the linear model ½‖Rδ − d‖² held by the Bayes tree, about θ: shrinks the
// trust region and retries while the error rises.
void ISAM2::apply_dogleg(ISAM2Result& res) {
  double error_theta = 0;
  for (size_t f = 0; f < graph_.size(); ++f) {
    if (graph_[f]) error_theta += linearized_[f].error;
  }
  const Eigen::VectorXd sd = cauchy_point();
  const Eigen::VectorXd& gn = delta_gn_;
  const double gn_norm = gn.norm();
  const double sd_norm = sd.norm();
  const double model_zero = tree_.model_cost(Eigen::VectorXd::Zero(delta_.size()));
  const std::vector<int> all = free_slots(theta_);
  const double slack = options_.error_rise_tolerance * std::max(std::abs(res.error_before), 1e-300);
  Eigen::VectorXd step(delta_.size());
  for (int trial = 0;; ++trial) {
    ++res.trials;
    const bool limited = dogleg_point(gn, gn_norm, sd, sd_norm, trust_radius_, step);
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

// Minimizer of the tree's linear model along the steepest-descent direction (zero where the
// gradient is).
Eigen::VectorXd ISAM2::cauchy_point() const {
  Eigen::VectorXd s(delta_.size());
  tree_.gradient(s);
  const double s2 = s.squaredNorm();
  const double Rs2 = tree_.r_norm_squared(s);
  return Rs2 > 0 ? Eigen::VectorXd((s2 / Rs2) * s) : Eigen::VectorXd::Zero(s.size());
}

std::string ISAM2::check_invariants() const {
  if (tree_deferred_ && tree_.empty()) return "";  // nothing to check until it is rebuilt
  std::vector<int> factors;
  for (size_t f = 0; f < graph_.size(); ++f) {
    if (!graph_[f]) continue;
    bool has_free = false;
    for (int s : factor_slots_[f]) has_free |= !theta_.is_fixed_slot(s);
    if (has_free) factors.push_back(static_cast<int>(f));
  }
  return tree_.check_invariants(free_slots(theta_), factors);
}

}  // namespace kinograph::graph

#include "kinograph/planning/solver/augmented_lagrangian.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <sstream>

#include "kinograph/graph/levenberg_marquardt.h"
#include "kinograph/graph/stopwatch.h"
#include "kinograph/graph/worker_pool.h"

namespace kinograph::planning {
namespace {

// Below this many constraint factors a scan stays on the caller's thread (waking the workers
// costs more than it saves).
constexpr size_t kMinSharedConstraints = 64;

// The first worst of the factors' violations, in their order (as a scan in order picks it).
ConstraintReport first_worst(const std::vector<const FactorEntry*>& constraints,
                             const std::vector<ConstrainedFactor::Violation>& violations) {
  ConstraintReport r;
  for (size_t i = 0; i < constraints.size(); ++i) {
    const ConstrainedFactor::Violation& v = violations[i];
    if (v.scaled > r.scaled_violation) {
      r.scaled_violation = v.scaled;
      r.violation = v.own_units;
      r.entry = constraints[i];
      r.row = v.row;
      r.value = v.value;
    }
  }
  if (r.entry != nullptr) {
    const ConstrainedFactor& worst = *r.entry->constrained;
    r.where = worst.name() + " " + worst.keys().front().to_string();
  }
  return r;
}

}  // namespace

AugmentedLagrangian::AugmentedLagrangian(std::vector<const FactorEntry*> constraints,
                                         ConstraintState& state,
                                         AugmentedLagrangianOptions options)
    : constraints_(std::move(constraints)), state_(state), options_(options) {
  for (const FactorEntry* e : constraints_) {
    state_.bind(*e);
    multipliers_.push_back(&state_.at(e->key));
  }
  state_.set_penalty(options_.initial_penalty);
}

ConstraintReport worst_constraint(const std::vector<const FactorEntry*>& constraints,
                                  const graph::Values& values) {
  // On the process's workers when there are many: after a solve the rows just added (the
  // interpolant's, integrated finely) are evaluated here for the first time. The multiplier
  // update below mostly reads kept values, too little work to share.
  std::vector<ConstrainedFactor::Violation> violations(constraints.size());
  auto check = [&](int i, int /*worker*/) {
    violations[static_cast<size_t>(i)] =
        constraints[static_cast<size_t>(i)]->constrained->check(values);
  };
  std::vector<int> caller_only, any;
  for (size_t i = 0; i < constraints.size(); ++i) {
    const bool shared =
        constraints.size() >= kMinSharedConstraints && constraints[i]->factor->parallel_safe();
    (shared ? any : caller_only).push_back(static_cast<int>(i));
  }
  graph::share_out(any.empty() ? 1 : graph::kMaxWorkers, caller_only, any, check);
  return first_worst(constraints, violations);
}

ConstraintReport AugmentedLagrangian::report(const graph::Values& values) const {
  return worst_constraint(constraints_, values);
}

double AugmentedLagrangian::update(const graph::Values& values) {
  return update_unless_within(values, -1).scaled_violation;
}

ConstraintReport AugmentedLagrangian::update_unless_within(const graph::Values& values,
                                                           double tolerance) {
  const bool may_keep = tolerance >= 0;
  if (may_keep) {
    saved_.resize(multipliers_.size());
    for (size_t i = 0; i < multipliers_.size(); ++i) saved_[i] = *multipliers_[i];
  }
  violations_.resize(constraints_.size());
  for (size_t i = 0; i < constraints_.size(); ++i) {
    violations_[i] = constraints_[i]->constrained->update_multipliers(values, *multipliers_[i]);
  }
  ConstraintReport r = first_worst(constraints_, violations_);  // worst_constraint's choice
  if (may_keep && r.scaled_violation <= tolerance) {
    for (size_t i = 0; i < multipliers_.size(); ++i) *multipliers_[i] = saved_[i];
    return r;
  }
  // At the largest μ, progress is a violation a tenth below the smallest seen there: slow but
  // steady progress (tight tolerances) is not a stall, a violation that wanders is.
  if (at_max_penalty()) {
    if (best_at_max_ >= 0 && r.scaled_violation > 0.9 * best_at_max_) {
      ++stalled_updates_;
    } else {
      stalled_updates_ = 0;
    }
    best_at_max_ = best_at_max_ < 0 ? r.scaled_violation
                                    : std::min(best_at_max_, r.scaled_violation);
  }
  if (last_violation_ >= 0 && r.scaled_violation > options_.required_decrease * last_violation_) {
    state_.set_penalty(std::min(options_.max_penalty, state_.penalty() * options_.penalty_growth));
  }
  last_violation_ = r.scaled_violation;
  return r;
}

namespace {
using Clock = std::chrono::steady_clock;
using graph::seconds_since;
}  // namespace

OuterLoopResult solve_outer_loop(const graph::FactorGraph& graph, graph::Values& values,
                                 AugmentedLagrangian& al, const OuterLoopOptions& options,
                                 const std::string& name) {
  const auto t0 = Clock::now();
  const graph::LevenbergMarquardtOptions default_lm;
  // A solve that starts at the largest μ (a re-solve projecting onto rows just added) keeps
  // that μ: its inner problems differ only in their multipliers.
  const bool carry_damping = options.damping_carry > 0 && al.at_max_penalty();
  graph::LevenbergMarquardtOptions lm_options;
  lm_options.record_history = false;
  lm_options.max_iterations = options.max_inner_iterations;
  lm_options.relative_error_tol = options.inner_tolerance_initial;
  graph::LevenbergMarquardt lm(lm_options);
  const double tol = options.constraint_tolerance, tol_final = options.inner_tolerance_final;
  OuterLoopResult out;
  double lm_s = 0;
  for (int outer = 0; outer < options.max_outer_iterations; ++outer) {
    lm_options.max_iterations =
        std::min(options.max_inner_iterations, options.max_total_iterations - out.iterations);
    if (lm_options.max_iterations <= 0) break;
    lm.set_options(lm_options);
    const graph::OptimizationResult r = lm.optimize(graph, values);
    lm_s += r.total_s;
    out.times.linearization_s += r.linearize_s + r.evaluate_s;
    out.times.factorization_s += r.symbolic_s + r.factorize_s;
    out.times.triangular_solve_s += r.solve_s;
    out.iterations += r.iterations;
    out.linear_solves += r.trials;
    out.outer_iterations = outer + 1;
    if (r.status == graph::SolverStatus::kNonFinite) {
      out.status = PlanStatus::kNonFinite;
      out.reason = r.reason;
      break;
    }
    const auto t_al = Clock::now();
    // Converged once feasible at the final inner tolerance (the slack absorbs the rounding of
    // the repeated 10× tightening); otherwise the multipliers move, from the same evaluation.
    const double mu = al.penalty();
    const bool final_tolerance = lm_options.relative_error_tol <= tol_final * 1.0001;
    const ConstraintReport worst = al.update_unless_within(values, final_tolerance ? tol : -1);
    spdlog::debug("AL outer {}: mu={:.3g} LM {} its ({}), cost {:.6g}, worst {:.3g} at {}", outer,
                  mu, r.iterations, graph::to_string(r.status), r.final_error,
                  worst.scaled_violation, worst.where);
    out.times.multipliers_s += seconds_since(t_al);
    if (final_tolerance && worst.scaled_violation <= tol) {
      out.status = PlanStatus::kConverged;
      out.worst = worst;
      break;
    }
    if (options.max_stalled_updates > 0 && al.stalled_updates() >= options.max_stalled_updates) {
      spdlog::debug("{}: the violation stalled at the largest penalty", name);
      break;
    }
    if (carry_damping) {
      lm_options.lambda_initial = std::clamp(options.damping_carry * r.lambda,
                                             default_lm.lambda_min, default_lm.lambda_initial);
    }
    // Feasible: one more solve at the final tolerance settles the objective.
    lm_options.relative_error_tol = worst.scaled_violation <= tol
                                        ? tol_final
                                        : std::max(tol_final, lm_options.relative_error_tol * 0.1);
  }
  if (out.status != PlanStatus::kConverged) out.worst = al.report(values);
  if (out.status == PlanStatus::kInfeasible && out.worst.scaled_violation <= tol) {
    out.status = PlanStatus::kConverged;
  }
  if (out.status == PlanStatus::kInfeasible) {
    std::ostringstream os;
    os << "constraints still violated after " << out.outer_iterations << " outer and "
       << out.iterations << " LM iterations: worst " << out.worst.violation << " at "
       << out.worst.where;
    out.reason = os.str();
  }
  spdlog::debug("{}: outer loop {:.1f} ms (LM {:.1f}, multipliers {:.1f})", name,
                1e3 * seconds_since(t0), 1e3 * lm_s, 1e3 * out.times.multipliers_s);
  return out;
}

}  // namespace kinograph::planning

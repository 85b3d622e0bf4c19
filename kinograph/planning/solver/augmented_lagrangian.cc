#include "kinograph/planning/solver/augmented_lagrangian.h"

#include <algorithm>

namespace kinograph::planning {

AugmentedLagrangian::AugmentedLagrangian(std::vector<std::shared_ptr<ConstrainedFactor>> factors,
                                         AugmentedLagrangianOptions options)
    : factors_(std::move(factors)), options_(options), mu_(options.initial_penalty) {
  set_penalty(mu_);
}

void AugmentedLagrangian::set_penalty(double mu) {
  mu_ = mu;
  for (auto& f : factors_) f->set_penalty(mu);
}

ConstraintReport AugmentedLagrangian::report(const graph::Values& values) const {
  ConstraintReport r;
  const ConstrainedFactor* worst = nullptr;
  for (const auto& f : factors_) {
    const ConstrainedFactor::Violation v = f->check(values);
    if (v.scaled > r.scaled_violation) {
      r.scaled_violation = v.scaled;
      r.violation = v.own_units;
      worst = f.get();
    }
  }
  if (worst != nullptr) r.where = worst->name() + " " + worst->keys().front().to_string();
  return r;
}

double AugmentedLagrangian::update(const graph::Values& values) {
  double worst = 0;
  for (auto& f : factors_) worst = std::max(worst, f->update_multipliers(values).scaled);
  if (last_violation_ >= 0 && worst > options_.required_decrease * last_violation_) {
    set_penalty(std::min(options_.max_penalty, mu_ * options_.penalty_growth));
  }
  last_violation_ = worst;
  return worst;
}

void AugmentedLagrangian::reset() {
  for (auto& f : factors_) f->reset_multipliers();
  last_violation_ = -1;
  set_penalty(options_.initial_penalty);
}

}  // namespace kinograph::planning

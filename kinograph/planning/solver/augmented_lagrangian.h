#pragma once
// The augmented-Lagrangian outer loop's state: the constraint factors of a graph, their shared
// penalty μ and the schedule that updates multipliers and grows μ. Changing them never changes
// the graph's structure, so warm-started LM solves reuse their symbolic analysis (and the
// incremental replanner can carry multipliers over from a previous plan).
#include <memory>
#include <string>
#include <vector>

#include "kinograph/graph/values.h"
#include "kinograph/planning/factors/constrained_factor.h"

namespace kinograph::planning {

/// Penalty schedule of AugmentedLagrangian.
struct AugmentedLagrangianOptions {
  double initial_penalty = 100;     ///< μ₀
  double penalty_growth = 10;       ///< μ ← growth·μ when the violation did not shrink enough
  double max_penalty = 1e7;         ///< μ never exceeds this
  double required_decrease = 0.25;  ///< violation must fall below this fraction of the last one
};

/// The worst constraint row of a graph, for reports.
struct ConstraintReport {
  double scaled_violation = 0;  ///< max |c| (violation / scale)
  double violation = 0;         ///< the same row's violation in its own units
  std::string where;            ///< factor name and first key, e.g. "DynamicsStepFactor q(0,12)"
};

/// Owns the schedule over a set of constraint factors (the factors hold the multipliers).
class AugmentedLagrangian {
 public:
  AugmentedLagrangian(std::vector<std::shared_ptr<ConstrainedFactor>> factors,
                      AugmentedLagrangianOptions options = {});

  /// Sets μ on every factor.
  void set_penalty(double mu);
  double penalty() const { return mu_; }
  /// The worst scaled violation at `values` and where it is.
  ConstraintReport report(const graph::Values& values) const;
  /// After an inner solve: λ ← λ + μc on every factor, then μ grows unless the worst scaled
  /// violation fell below required_decrease × the previous one. Returns that violation.
  double update(const graph::Values& values);
  /// Zeroes all multipliers and sets μ₀.
  void reset();

  const std::vector<std::shared_ptr<ConstrainedFactor>>& factors() const { return factors_; }

 private:
  std::vector<std::shared_ptr<ConstrainedFactor>> factors_;
  AugmentedLagrangianOptions options_;
  double mu_;
  double last_violation_ = -1;
};

}  // namespace kinograph::planning

#pragma once
// Factors the incremental replanner needs beyond the batch graph: the start state and a joint
// goal as equality constraints on (unfixed) state variables, so that changing them is a factor
// replacement in ISAM2 (which cannot change a variable's fixed flag or value).
#include <Eigen/Core>
#include <memory>
#include <vector>

#include "kinograph/graph/key.h"
#include "kinograph/planning/factors/constrained_factor.h"

namespace kinograph::planning {

/// Equality rows x_i = target_i on the stacked variables `keys` (all of dimension n), scaled
/// by `scale` (so the augmented Lagrangian's tolerance reads as tolerance·scale in the
/// variables' units). Linear: Gauss–Newton satisfies it in one step whatever its weight.
class StateTargetFactor final : public ConstrainedFactor {
 public:
  /// Equality rows (augmented Lagrangian).
  /// Throws std::invalid_argument if target's size is not keys.size()·n or scale ≤ 0.
  StateTargetFactor(std::vector<graph::Key> keys, int n, const Eigen::VectorXd& target,
                    double scale);
  /// A strong soft prior instead: rows weight·(x_i − target_i), outside the augmented Lagrangian
  /// (its weight does not grow with μ). Throws std::invalid_argument as above for weight ≤ 0.
  static std::shared_ptr<StateTargetFactor> soft(std::vector<graph::Key> keys, int n,
                                                 const Eigen::VectorXd& target, double weight);
  void compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
               const graph::Jacobians* J) const override;
  bool parallel_safe() const override { return true; }  // touches only its own state
  std::string describe_row(int row, double z, const RowContext& c) const override;
  /// The stacked target (the rows' `lower`).
  Eigen::VectorXd target() const;

 private:
  StateTargetFactor(std::vector<graph::Key> keys, int n, std::vector<RowSpec> rows);
  int n_;
};

}  // namespace kinograph::planning

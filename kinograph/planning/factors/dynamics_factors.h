#pragma once
// The condensed dynamics of one step: τ = RNEA(q, q̇, q̈) eliminated into the terms that use it —
// effort limits, unactuated joints (τ_j = 0) and the minimum-torque objective — so the inverse
// dynamics and its derivatives are computed once per state and linearization.
#include <memory>
#include <vector>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/planning/factors/constrained_factor.h"
#include "kinograph/planning/factors/dynamics_workspace.h"

namespace kinograph::planning {

/// Options of DynamicsStepFactor.
struct DynamicsStepOptions {
  double limit_epsilon = 0;  ///< effort limits are tightened to ±(effort − ε)
  double min_torque = 0;     ///< w of the soft term w·Σ_j τ_j² (0 = no soft rows)
  double torque_scale = 1;   ///< scale s (N·m) of the effort and unactuated rows
};

/// Per-state dynamics of an n-joint arm with keys q_k, q̇_k, q̈_k. Rows: for each unactuated
/// joint an equality τ_j = 0, for each actuated joint with a finite effort limit a bound
/// |τ_j| ≤ effort − ε; then, if min_torque > 0, n soft rows √(2w)·τ_j. Jacobians from
/// dynamics::rnea_derivatives. Shares a DynamicsWorkspace with its siblings.
class DynamicsStepFactor final : public ConstrainedFactor {
 public:
  /// Throws std::invalid_argument if the step would have no rows.
  DynamicsStepFactor(int k, std::shared_ptr<const dynamics::Model> model,
                     std::shared_ptr<DynamicsWorkspace> workspace, const DynamicsStepOptions& options);
  void compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
               const graph::Jacobians* J) const override;
  std::string describe_row(int row, double z, const RowContext& c) const override;
  bool parallel_safe() const override { return true; }

  /// Rows this factor would have for `model` (also used to tell whether it is needed).
  static std::vector<RowSpec> rows_for(const dynamics::Model& model,
                                       const DynamicsStepOptions& options,
                                       std::vector<int>* joint_of_row = nullptr);
  /// The joint whose torque each row holds.
  const std::vector<int>& joint_of_row() const { return joint_of_row_; }

 private:
  std::shared_ptr<const dynamics::Model> model_;
  std::shared_ptr<DynamicsWorkspace> data_;
  std::vector<int> joint_of_row_;
  bool bounds_only_ = false;  // every row a torque bound (no equality, no minimum torque)
};

}  // namespace kinograph::planning

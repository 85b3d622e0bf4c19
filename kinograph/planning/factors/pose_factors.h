#pragma once
// Pose constraints through forward kinematics: the end-effector pose goal on the last state and
// the task constraint (e.g. keep a carried block level) on every state.
#include <Eigen/Geometry>
#include <memory>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/planning/factors/constrained_factor.h"
#include "kinograph/planning/factors/dynamics_workspace.h"

namespace kinograph::planning {

/// Which parts of a frame's pose a PoseFactor constrains.
enum class PoseParts { kFull, kPosition, kOrientation };

/// Equality constraint on the world pose of `frame` at state k (key q_k): position rows p − p*
/// (m) and/or orientation rows ½ vee(R*ᵀR − RᵀR*) (= sin θ·axis in the target frame, zero at
/// R = R*). Orientation rows come first. Jacobians from the space and point Jacobians.
class PoseFactor final : public ConstrainedFactor {
 public:
  /// Throws std::out_of_range for an unknown frame.
  PoseFactor(int k, std::shared_ptr<const dynamics::Model> model,
             std::shared_ptr<DynamicsWorkspace> workspace, const std::string& frame,
             const Eigen::Isometry3d& target, PoseParts parts, double scale);
  void compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
               const graph::Jacobians* J) const override;
  bool parallel_safe() const override { return true; }  // touches only its own state
  std::string describe_row(int row, double z, const RowContext& c) const override;
  /// The frame's name in the model.
  const std::string& frame_name() const { return model_->frames[frame_].name; }
  /// Whether row `row` is an orientation row (else a position row, m).
  bool orientation_row(int row) const { return orientation_ && row < 3; }

 private:
  std::shared_ptr<const dynamics::Model> model_;
  std::shared_ptr<DynamicsWorkspace> data_;
  int frame_;
  int body_;
  Eigen::Isometry3d target_;
  bool position_, orientation_;
  mutable Eigen::Matrix<double, 6, Eigen::Dynamic> J6_;
  mutable Eigen::Matrix3Xd J3_;
};

}  // namespace kinograph::planning

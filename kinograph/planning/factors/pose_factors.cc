#include "kinograph/planning/factors/pose_factors.h"

#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/factors/trajectory_factors.h"
#include "kinograph/planning/user_terms.h"

namespace kinograph::planning {
namespace {

std::vector<RowSpec> pose_rows(PoseParts parts, double scale) {
  const int n = parts == PoseParts::kFull ? 6 : 3;
  RowSpec r;
  r.kind = RowKind::kEquality;
  r.scale = scale;
  return std::vector<RowSpec>(n, r);
}

Eigen::Vector3d vee_skew_part(const Eigen::Matrix3d& M) {
  // ½ vee(M − Mᵀ)
  return 0.5 * Eigen::Vector3d(M(2, 1) - M(1, 2), M(0, 2) - M(2, 0), M(1, 0) - M(0, 1));
}

}  // namespace

PoseFactor::PoseFactor(int k, std::shared_ptr<const dynamics::Model> model,
                       std::shared_ptr<DynamicsWorkspace> workspace, const std::string& frame,
                       const Eigen::Isometry3d& target, PoseParts parts, double scale)
    : ConstrainedFactor({q_key(k)}, {model->nq()}, pose_rows(parts, scale)),
      model_(std::move(model)),
      data_(std::move(workspace)),
      frame_(model_->frame_index(frame)),
      body_(model_->frames[frame_].body),
      target_(target),
      position_(parts != PoseParts::kOrientation),
      orientation_(parts != PoseParts::kPosition),
      J6_(6, model_->nq()),
      J3_(3, model_->nq()) {}

void PoseFactor::compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
                         const graph::Jacobians* J) const {
  dynamics::Data& d = data_->local();
  dynamics::forward_kinematics(*model_, d, x[0]);
  const Eigen::Isometry3d T = dynamics::frame_pose(*model_, d, frame_);
  const Eigen::Matrix3d Rt = target_.linear().transpose();
  const Eigen::Matrix3d M = Rt * T.linear();
  int row = 0;
  if (orientation_) {
    z.segment<3>(0) = vee_skew_part(M);
    row = 3;
  }
  if (position_) z.segment<3>(row) = T.translation() - target_.translation();
  if (J == nullptr || body_ < 0) return;
  auto B = J->block(0);
  if (orientation_) {
    dynamics::space_jacobian(*model_, d, body_, J6_);
    for (int j = 0; j < model_->nq(); ++j) {
      const Eigen::Vector3d u = Rt * J6_.block<3, 1>(0, j);
      Eigen::Matrix3d U;
      U << 0, -u.z(), u.y(), u.z(), 0, -u.x(), -u.y(), u.x(), 0;
      B.block<3, 1>(0, j) = vee_skew_part(U * M);  // d(M − Mᵀ)/2 with dM = [u]M
    }
  }
  if (position_) {
    dynamics::point_jacobian(*model_, d, body_, T.translation(), J3_);
    B.block(row, 0, 3, model_->nq()) = J3_;
  }
}

std::string PoseFactor::describe_row(int row, double, const RowContext& c) const {
  const bool rotation = orientation_row(row);
  const std::string off =
      rotation ? number(c.violation) + " (sine of the angle)" : number(c.violation) + " m";
  const std::string what = rotation ? "orientation" : "position";
  if (c.index >= 0) {
    return "task constraint " + std::to_string(c.index + 1) + " on frame '" + frame_name() +
           "' is off in " + what + " by " + off + " at " + at_time(c.t);
  }
  return "frame '" + frame_name() + "' misses its goal " + what + " by " + off + " at " +
         at_time(c.t);
}

}  // namespace kinograph::planning

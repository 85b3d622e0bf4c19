#include "kinograph/dynamics/kinematics.h"

#include "kinograph/dynamics/kinematics_detail.h"

namespace kinograph::dynamics {

void forward_kinematics(const Model& model, Data& data,
                        const Eigen::Ref<const Eigen::VectorXd>& q) {
  detail::update_poses(model, data, q);
}

Eigen::Isometry3d frame_pose(const Model& model, const Data& data, int frame) {
  const Frame& f = model.frames.at(frame);
  if (f.body < 0) return f.placement;
  return data.body_pose[f.body] * f.placement;
}

void space_jacobian(const Model& model, const Data& data, int body,
                    Eigen::Ref<Eigen::Matrix<double, 6, Eigen::Dynamic>> J) {
  J.setZero();
  for (int j = body; j >= 0; j = model.bodies[j].parent) {
    J.col(j) = Ad_apply(data.body_pose[j], model.bodies[j].screw_axis);
  }
}

void point_jacobian(const Model& model, const Data& data, int body,
                    const Eigen::Vector3d& point_world, Eigen::Ref<Eigen::Matrix3Xd> J) {
  J.setZero();
  for (int j = body; j >= 0; j = model.bodies[j].parent) {
    const Vector6 S = Ad_apply(data.body_pose[j], model.bodies[j].screw_axis);
    // Velocity of a point of a body moving with spatial twist [ω; v]: v + ω × p.
    J.col(j) = S.tail<3>() + S.head<3>().cross(point_world);
  }
}

}  // namespace kinograph::dynamics

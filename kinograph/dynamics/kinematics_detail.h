#pragma once
// Internal helpers shared by the kinematics and dynamics sources (not installed API).
#include <Eigen/Geometry>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/model.h"

namespace kinograph::dynamics::detail {

/// T_parent,body(q) = parent_to_joint · exp([A] q) for a unit revolute or prismatic screw A.
inline void joint_transform(const Body& b, double q, Eigen::Isometry3d& out) {
  if (b.joint_type == JointType::kRevolute) {
    const Eigen::Vector3d axis = b.screw_axis.head<3>();
    out.linear().noalias() =
        b.parent_to_joint.linear() * Eigen::AngleAxisd(q, axis).toRotationMatrix();
    out.translation() = b.parent_to_joint.translation();
  } else {
    out.linear() = b.parent_to_joint.linear();
    out.translation() =
        b.parent_to_joint.translation() + b.parent_to_joint.linear() * (b.screw_axis.tail<3>() * q);
  }
}

/// Fills scratch.joint_pose and body_pose for joint positions q.
inline void update_poses(const Model& model, Data& data,
                         const Eigen::Ref<const Eigen::VectorXd>& q) {
  const int n = model.nq();
  for (int i = 0; i < n; ++i) {
    const Body& b = model.bodies[i];
    Eigen::Isometry3d& Tj = data.scratch.joint_pose[i];
    joint_transform(b, q[i], Tj);
    if (b.parent < 0) {
      data.body_pose[i] = Tj;
    } else {
      const Eigen::Isometry3d& P = data.body_pose[b.parent];
      data.body_pose[i].linear().noalias() = P.linear() * Tj.linear();
      data.body_pose[i].translation() = P.translation() + P.linear() * Tj.translation();
    }
  }
}

}  // namespace kinograph::dynamics::detail

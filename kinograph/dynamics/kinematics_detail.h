#pragma once
// Internal helpers shared by the kinematics and dynamics sources (not installed API).
#include <Eigen/Geometry>
#include <cmath>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/model.h"

namespace kinograph::dynamics::detail {

/// Columns i, j of P · Rot_k(θ) for the coordinate axis k after which i, j follow cyclically
/// (x: y, z; y: z, x; z: x, y): the rotation mixes only those two columns, and column k stays.
inline void rotate_columns(const Eigen::Matrix3d& P, int i, int j, double c, double s,
                           Eigen::Matrix3d& out) {
  out.col(i) = c * P.col(i) + s * P.col(j);
  out.col(j) = c * P.col(j) - s * P.col(i);
}

/// T_parent,body(q) = parent_to_joint · exp([A] q) for a unit revolute or prismatic screw A.
/// Revolute joints about a coordinate axis (every joint of the iiwa, most URDFs) skip the
/// general axis-angle matrix and its 3 × 3 product: two columns of parent_to_joint mix, with
/// the same roundings as the general form (the dropped terms are exact zeros).
inline void joint_transform(const Body& b, double q, Eigen::Isometry3d& out) {
  if (b.joint_type == JointType::kRevolute) {
    const Eigen::Vector3d axis = b.screw_axis.head<3>();
    const Eigen::Matrix3d& P = b.parent_to_joint.linear();
    out.translation() = b.parent_to_joint.translation();
    for (int k = 0; k < 3; ++k) {
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      if (axis[i] != 0 || axis[j] != 0 || std::abs(axis[k]) != 1) continue;
      const double c = std::cos(q), s = axis[k] * std::sin(q);
      Eigen::Matrix3d R;
      // (1 − c) + c is the axis-angle formula's diagonal entry for the axis, which rounds off 1
      // by an ulp for some angles: kept so that poses are bitwise those of the general form.
      R.col(k) = P.col(k) * ((1 - c) + c);
      rotate_columns(P, i, j, c, s, R);
      out.linear() = R;
      return;
    }
    out.linear().noalias() = P * Eigen::AngleAxisd(q, axis).toRotationMatrix();
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

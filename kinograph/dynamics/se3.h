#pragma once
// SE(3) and se(3) algebra in the conventions of Lynch & Park, Modern Robotics, ch. 3 and 8:
// twists V = [ω; v], wrenches F = [m; f], both 6-vectors with the angular part first.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace kinograph::dynamics {

using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;

/// [w]: the skew-symmetric matrix with [w] x = w × x (MR eq. 3.30).
Eigen::Matrix3d skew(const Eigen::Vector3d& w);

/// [Ad_T]: maps a twist in the frame of T's child to T's parent frame (MR eq. 3.83).
/// Its transpose maps wrenches the other way: F_child = Ad_T^T F_parent (MR eq. 3.95).
Matrix6 Ad(const Eigen::Isometry3d& T);

/// [Ad_T]^{-1} = [Ad_{T^{-1}}], built without inverting a 6×6 matrix.
Matrix6 Ad_inv(const Eigen::Isometry3d& T);

/// [ad_V]: the Lie bracket of twists, [ad_V] W = [V, W] (MR eq. 8.38).
Matrix6 ad(const Vector6& V);

/// Matrix exponential of a twist: the pose reached after following screw ξ for unit time
/// (MR eq. 3.88 for a unit screw times θ, here for any ξ).
Eigen::Isometry3d exp_se3(const Vector6& xi);

/// Inverse of exp_se3 on the principal branch (rotation angle in [0, π]) (MR algorithm 3.2).
Vector6 log_se3(const Eigen::Isometry3d& T);

/// Ad_T V without forming the 6×6 matrix (hot paths).
inline Vector6 Ad_apply(const Eigen::Isometry3d& T, const Vector6& V) {
  Vector6 out;
  const Eigen::Matrix3d& R = T.linear();
  out.head<3>() = R * V.head<3>();
  out.tail<3>() = T.translation().cross(out.head<3>()) + R * V.tail<3>();
  return out;
}

/// Ad_T^{-1} V = Ad_{T^{-1}} V without forming the 6×6 matrix.
inline Vector6 Ad_inv_apply(const Eigen::Isometry3d& T, const Vector6& V) {
  Vector6 out;
  const Eigen::Matrix3d& R = T.linear();
  out.head<3>() = R.transpose() * V.head<3>();
  out.tail<3>() = R.transpose() * (V.tail<3>() - T.translation().cross(V.head<3>()));
  return out;
}

/// Ad_T^T F: a wrench given in T's parent frame re-expressed in T's child frame.
inline Vector6 Ad_transpose_apply(const Eigen::Isometry3d& T, const Vector6& F) {
  Vector6 out;
  const Eigen::Matrix3d& R = T.linear();
  out.head<3>() = R.transpose() * (F.head<3>() + F.tail<3>().cross(T.translation()));
  out.tail<3>() = R.transpose() * F.tail<3>();
  return out;
}

/// Ad_{T^{-1}}^T F: a wrench given in T's child frame re-expressed in T's parent frame.
inline Vector6 Ad_inv_transpose_apply(const Eigen::Isometry3d& T, const Vector6& F) {
  Vector6 out;
  const Eigen::Matrix3d& R = T.linear();
  out.tail<3>() = R * F.tail<3>();
  out.head<3>() = R * F.head<3>() + T.translation().cross(out.tail<3>());
  return out;
}

/// [ad_V] W = V × W for twists (the motion cross product), without the 6×6 matrix.
inline Vector6 ad_apply(const Vector6& V, const Vector6& W) {
  Vector6 out;
  out.head<3>() = V.head<3>().cross(W.head<3>());
  out.tail<3>() = V.head<3>().cross(W.tail<3>()) + V.tail<3>().cross(W.head<3>());
  return out;
}

/// [ad_V]^T F for a wrench F (MR eq. 8.42 uses −[ad_V]^T F as the gyroscopic wrench).
inline Vector6 ad_transpose_apply(const Vector6& V, const Vector6& F) {
  Vector6 out;
  out.head<3>() = F.head<3>().cross(V.head<3>()) + F.tail<3>().cross(V.tail<3>());
  out.tail<3>() = F.tail<3>().cross(V.head<3>());
  return out;
}

}  // namespace kinograph::dynamics

#include "kinograph/dynamics/se3.h"

#include <cmath>

namespace kinograph::dynamics {

Eigen::Matrix3d skew(const Eigen::Vector3d& w) {
  Eigen::Matrix3d m;
  m << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return m;
}

Matrix6 Ad(const Eigen::Isometry3d& T) {
  Matrix6 m = Matrix6::Zero();
  const Eigen::Matrix3d R = T.linear();
  m.topLeftCorner<3, 3>() = R;
  m.bottomRightCorner<3, 3>() = R;
  m.bottomLeftCorner<3, 3>() = skew(T.translation()) * R;
  return m;
}

Matrix6 Ad_inv(const Eigen::Isometry3d& T) {
  Matrix6 m = Matrix6::Zero();
  const Eigen::Matrix3d Rt = T.linear().transpose();
  m.topLeftCorner<3, 3>() = Rt;
  m.bottomRightCorner<3, 3>() = Rt;
  m.bottomLeftCorner<3, 3>() = -Rt * skew(T.translation());
  return m;
}

Matrix6 ad(const Vector6& V) {
  Matrix6 m = Matrix6::Zero();
  const Eigen::Matrix3d w = skew(V.head<3>());
  m.topLeftCorner<3, 3>() = w;
  m.bottomRightCorner<3, 3>() = w;
  m.bottomLeftCorner<3, 3>() = skew(V.tail<3>());
  return m;
}

Eigen::Isometry3d exp_se3(const Vector6& xi) {
  const Eigen::Vector3d w = xi.head<3>();
  const Eigen::Vector3d v = xi.tail<3>();
  const double theta2 = w.squaredNorm();
  const double theta = std::sqrt(theta2);
  // Coefficients of [w] and [w]^2 in R (Rodrigues) and in the left Jacobian V (MR eq. 3.88),
  // with Taylor series near θ = 0 where the closed forms cancel catastrophically.
  double a, b, c;
  if (theta < 1e-4) {
    a = 1.0 - theta2 / 6.0;
    b = 0.5 - theta2 / 24.0;
    c = 1.0 / 6.0 - theta2 / 120.0;
  } else {
    a = std::sin(theta) / theta;
    b = (1.0 - std::cos(theta)) / theta2;
    c = (theta - std::sin(theta)) / (theta2 * theta);
  }
  const Eigen::Matrix3d W = skew(w);
  const Eigen::Matrix3d W2 = W * W;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Matrix3d::Identity() + a * W + b * W2;
  T.translation() = (Eigen::Matrix3d::Identity() + b * W + c * W2) * v;
  return T;
}

Vector6 log_se3(const Eigen::Isometry3d& T) {
  const Eigen::AngleAxisd aa(T.linear());
  const double theta = aa.angle();
  const Eigen::Vector3d w = aa.axis() * theta;
  // Inverse of the left Jacobian: I − ½[w] + k [w]², k = 1/θ² − cot(θ/2)/(2θ); the cot form
  // stays finite at θ = π, the series avoids cancellation near 0.
  double k;
  if (theta < 1e-4) {
    k = 1.0 / 12.0 + theta * theta / 720.0;
  } else {
    k = 1.0 / (theta * theta) - 1.0 / (2.0 * theta * std::tan(0.5 * theta));
  }
  const Eigen::Matrix3d W = skew(w);
  Vector6 xi;
  xi.head<3>() = w;
  xi.tail<3>() = (Eigen::Matrix3d::Identity() - 0.5 * W + k * W * W) * T.translation();
  return xi;
}

}  // namespace kinograph::dynamics

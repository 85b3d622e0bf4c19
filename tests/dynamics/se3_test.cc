// SE(3) identities: Ad is a homomorphism, ad is the derivative of Ad, exp and log invert each
// other, and the matrix-free helpers equal their matrix forms.
#include "kinograph/dynamics/se3.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace kinograph::dynamics {
namespace {

Vector6 random_twist(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Vector6 v;
  for (int i = 0; i < 6; ++i) v[i] = u(rng);
  return v;
}

Eigen::Isometry3d random_pose(std::mt19937& rng) { return exp_se3(random_twist(rng, 1.5)); }

TEST(Se3, SkewIsCrossProduct) {
  const Eigen::Vector3d a(0.3, -1.2, 2.0), b(-0.7, 0.4, 1.1);
  EXPECT_TRUE((skew(a) * b).isApprox(a.cross(b), 1e-14));
  EXPECT_TRUE((skew(a) + skew(a).transpose()).isZero(0));
}

TEST(Se3, AdOfProductIsProductOfAd) {
  std::mt19937 rng(1);
  for (int k = 0; k < 50; ++k) {
    const Eigen::Isometry3d A = random_pose(rng), B = random_pose(rng);
    EXPECT_TRUE(Ad(A * B).isApprox(Ad(A) * Ad(B), 1e-12));
    EXPECT_TRUE((Ad(A) * Ad_inv(A)).isIdentity(1e-12));
    EXPECT_TRUE(Ad_inv(A).isApprox(Ad(A.inverse()), 1e-12));
  }
}

TEST(Se3, AdMapsTwistsLikeConjugation) {
  // [Ad_T V] = T [V] T^{-1} as 4×4 matrices (MR eq. 3.83).
  std::mt19937 rng(2);
  auto hat = [](const Vector6& V) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
    m.topLeftCorner<3, 3>() = skew(V.head<3>());
    m.topRightCorner<3, 1>() = V.tail<3>();
    return m;
  };
  for (int k = 0; k < 20; ++k) {
    const Eigen::Isometry3d T = random_pose(rng);
    const Vector6 V = random_twist(rng, 2.0);
    EXPECT_TRUE(hat(Ad(T) * V).isApprox(T.matrix() * hat(V) * T.inverse().matrix(), 1e-12));
  }
}

TEST(Se3, AdIsDerivativeOfAdAlongExp) {
  // d/dt Ad(exp(t V)) at t = 0 equals ad(V); central differences.
  std::mt19937 rng(3);
  const double h = 1e-6;
  for (int k = 0; k < 20; ++k) {
    const Vector6 V = random_twist(rng, 1.0);
    const Matrix6 d = (Ad(exp_se3(h * V)) - Ad(exp_se3(-h * V))) / (2 * h);
    EXPECT_TRUE(d.isApprox(ad(V), 1e-8)) << d << "\n\n" << ad(V);
  }
}

TEST(Se3, AdIsLieBracketAndEquivariant) {
  std::mt19937 rng(4);
  for (int k = 0; k < 20; ++k) {
    const Vector6 V = random_twist(rng, 1.0), W = random_twist(rng, 1.0);
    const Eigen::Isometry3d T = random_pose(rng);
    EXPECT_TRUE((ad(V) * W).isApprox(-(ad(W) * V), 1e-12));
    EXPECT_TRUE(ad(Ad(T) * V).isApprox(Ad(T) * ad(V) * Ad_inv(T), 1e-12));
  }
}

TEST(Se3, ExpLogRoundTrip) {
  std::mt19937 rng(5);
  for (int k = 0; k < 200; ++k) {
    Vector6 xi = random_twist(rng, 2.0);
    // Keep the rotation angle inside the principal branch [0, π).
    if (xi.head<3>().norm() >= M_PI) xi.head<3>() *= 3.0 / xi.head<3>().norm();
    EXPECT_TRUE(log_se3(exp_se3(xi)).isApprox(xi, 1e-10)) << xi.transpose();
    const Eigen::Isometry3d T = random_pose(rng);
    EXPECT_TRUE(exp_se3(log_se3(T)).isApprox(T, 1e-10));
  }
}

TEST(Se3, ExpLogNearZeroAndNearPi) {
  for (double theta : {0.0, 1e-9, 1e-6, 1e-4, 1e-3, M_PI - 1e-3, M_PI - 1e-6}) {
    Vector6 xi;
    xi << Eigen::Vector3d(1, -2, 0.5).normalized() * theta, 0.4, -0.3, 1.2;
    const Eigen::Isometry3d T = exp_se3(xi);
    EXPECT_TRUE(exp_se3(log_se3(T)).isApprox(T, 1e-9)) << theta;
    EXPECT_NEAR((T.linear() * T.linear().transpose() - Eigen::Matrix3d::Identity()).norm(), 0,
                1e-14);
    if (theta < 3.0) {
      EXPECT_TRUE(log_se3(T).isApprox(xi, 1e-9)) << theta;
    }
  }
}

TEST(Se3, ExpMatchesClosedFormScrewMotion) {
  // A unit rotation screw about z through (1, 0, 0) by π/2 maps the origin to (1, -1, 0).
  Vector6 xi;
  const Eigen::Vector3d w(0, 0, 1), q(1, 0, 0);
  xi << w, -w.cross(q);
  const Eigen::Isometry3d T = exp_se3(xi * M_PI / 2);
  EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(1, -1, 0), 1e-12));
  EXPECT_TRUE(T.linear().isApprox(Eigen::AngleAxisd(M_PI / 2, w).toRotationMatrix(), 1e-12));
}

TEST(Se3, MatrixFreeHelpersMatchMatrices) {
  std::mt19937 rng(6);
  for (int k = 0; k < 20; ++k) {
    const Eigen::Isometry3d T = random_pose(rng);
    const Vector6 V = random_twist(rng, 2.0), F = random_twist(rng, 2.0);
    EXPECT_TRUE(Ad_apply(T, V).isApprox(Ad(T) * V, 1e-12));
    EXPECT_TRUE(Ad_inv_apply(T, V).isApprox(Ad_inv(T) * V, 1e-12));
    EXPECT_TRUE(Ad_transpose_apply(T, F).isApprox(Ad(T).transpose() * F, 1e-12));
    EXPECT_TRUE(Ad_inv_transpose_apply(T, F).isApprox(Ad_inv(T).transpose() * F, 1e-12));
    EXPECT_TRUE(ad_apply(V, F).isApprox(ad(V) * F, 1e-12));
    EXPECT_TRUE(ad_transpose_apply(V, F).isApprox(ad(V).transpose() * F, 1e-12));
    // Power is frame invariant: (Ad_T^T F)·V = F·(Ad_T V).
    EXPECT_NEAR(Ad_transpose_apply(T, F).dot(V), F.dot(Ad_apply(T, V)), 1e-12);
  }
}

}  // namespace
}  // namespace kinograph::dynamics

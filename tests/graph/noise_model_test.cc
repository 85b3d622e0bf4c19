// Noise models against their closed forms, and the hinge limit's three regimes.
#include "kinograph/graph/noise_model.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <limits>
#include <random>

#include "kinograph/graph/prior_factor.h"
#include "kinograph/graph/testing/numerical_jacobian.h"

namespace kinograph::graph {
namespace {

TEST(NoiseModel, IsotropicAndDiagonalDivideBySigma) {
  Eigen::VectorXd e(3);
  e << 1, -2, 4;
  Eigen::MatrixXd J = Eigen::MatrixXd::Ones(3, 2);
  isotropic(3, 2.0)->whiten_system(e, J);
  EXPECT_TRUE(e.isApprox(Eigen::Vector3d(0.5, -1, 2)));
  EXPECT_TRUE(J.isApprox(Eigen::MatrixXd::Constant(3, 2, 0.5)));
  e << 1, -2, 4;
  J.setOnes();
  diagonal(Eigen::Vector3d(1, 2, 4))->whiten_system(e, J);
  EXPECT_TRUE(e.isApprox(Eigen::Vector3d(1, -1, 1)));
  EXPECT_TRUE(J.col(1).isApprox(Eigen::Vector3d(1, 0.5, 0.25)));
  EXPECT_THROW(isotropic(3, 0.0), std::invalid_argument);
  EXPECT_THROW(diagonal(Eigen::Vector2d(1, -1)), std::invalid_argument);
}

TEST(NoiseModel, GaussianGivesMahalanobisNorm) {
  std::mt19937 rng(3);
  std::normal_distribution<double> N;
  Eigen::MatrixXd A(5, 5);
  for (int i = 0; i < 25; ++i) A(i / 5, i % 5) = N(rng);
  const Eigen::MatrixXd cov = A * A.transpose() + 0.5 * Eigen::MatrixXd::Identity(5, 5);
  Eigen::VectorXd e(5);
  for (int i = 0; i < 5; ++i) e[i] = N(rng);
  const double expected = e.dot(cov.ldlt().solve(e));
  for (const auto& noise : {gaussian_covariance(cov), gaussian_information(cov.inverse())}) {
    Eigen::VectorXd r = e;
    Eigen::MatrixXd J = Eigen::MatrixXd::Identity(5, 5);
    noise->whiten_system(r, J);
    EXPECT_NEAR(r.squaredNorm(), expected, 1e-9 * expected);
    // J started as I, so it now holds R with RᵀR = Σ⁻¹, and R is upper triangular.
    EXPECT_TRUE((J.transpose() * J).isApprox(cov.inverse(), 1e-9));
    EXPECT_NEAR(J.triangularView<Eigen::StrictlyLower>().toDenseMatrix().norm(), 0.0, 1e-15);
    Eigen::VectorXd r2 = e;
    noise->whiten_residual(r2);
    EXPECT_TRUE(r2.isApprox(r));
  }
  Eigen::Matrix2d indefinite;
  indefinite << 1, 2, 2, 1;
  EXPECT_THROW(gaussian_covariance(indefinite), std::invalid_argument);
}

TEST(NoiseModel, HingeIsZeroInsideAndLinearOutside) {
  // Paper's c_limit with z_l = -1, z_u = 2, eps = 0.1, a = 3.
  const auto h =
      hinge(Eigen::VectorXd::Constant(1, -1.0), Eigen::VectorXd::Constant(1, 2.0), 0.1, 3.0);
  auto value = [&](double z, double* slope) {
    Eigen::VectorXd e = Eigen::VectorXd::Constant(1, z);
    Eigen::MatrixXd J = Eigen::MatrixXd::Ones(1, 1);
    h->whiten_system(e, J);
    *slope = J(0, 0);
    return e[0];
  };
  double s;
  EXPECT_DOUBLE_EQ(value(0.5, &s), 0.0);
  EXPECT_DOUBLE_EQ(s, 0.0);
  EXPECT_DOUBLE_EQ(value(-1.5, &s), 3.0 * (-1.0 + 1.5 + 0.1));
  EXPECT_DOUBLE_EQ(s, -3.0);
  EXPECT_DOUBLE_EQ(value(-0.95, &s), 3.0 * (-1.0 + 0.95 + 0.1));  // inside the ε band: costs
  EXPECT_DOUBLE_EQ(value(2.5, &s), 3.0 * (2.5 - 2.0 + 0.1));
  EXPECT_DOUBLE_EQ(s, 3.0);
  EXPECT_NEAR(value(-0.9, &s), 0.0, 1e-15);  // continuous at z_l + ε
  EXPECT_THROW(
      hinge(Eigen::VectorXd::Constant(1, 0.0), Eigen::VectorXd::Constant(1, 0.1), 0.1, 1.0),
      std::invalid_argument);
}

TEST(NoiseModel, OneSidedHingeAndCheckerOnWhitenedHinge) {
  const double inf = std::numeric_limits<double>::infinity();
  // A prior-shaped factor (e = x − 0) under a lower bound only, as a collision distance would be.
  auto f = std::make_shared<PriorFactor>(
      Key('d', 0, 0), Eigen::Vector2d::Zero(),
      hinge(Eigen::Vector2d(0.2, 0.2), Eigen::Vector2d(inf, inf), 0.05, 2.0));
  Values v;
  v.insert(Key('d', 0, 0), Eigen::Vector2d(0.1, 5.0));  // first active, second far inside
  EXPECT_NEAR(f->error(v), 0.5 * std::pow(2.0 * (0.2 - 0.1 + 0.05), 2), 1e-15);
  testing::JacobianCheckOptions o;
  o.whitened = true;
  const auto check = testing::check_jacobians(*f, v, o);
  EXPECT_TRUE(check.ok) << check.report();
  EXPECT_NEAR(check.blocks[0].analytic(0, 0), -2.0, 1e-15);
  EXPECT_EQ(check.blocks[0].analytic(1, 1), 0.0);
}

}  // namespace
}  // namespace kinograph::graph

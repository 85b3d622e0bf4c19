// Acrobot inverse dynamics against Spong's closed form (Tedrake/Drake convention: θ1 from the
// downward vertical, θ2 relative), including joint damping 0.1 as τ += b q̇.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/model.h"
#include "test_util.h"

namespace kinograph::dynamics {
namespace {

// Spong's Acrobot in Drake's convention (θ1 from the downward vertical, θ2 relative to link 1;
// parameters in robots/README.md): τ = M q̈ + C q̇ − τ_g + b q̇.
Eigen::Vector2d closed_form(const Eigen::Vector2d& q, const Eigen::Vector2d& qd,
                            const Eigen::Vector2d& qdd) {
  const double m1 = 1, m2 = 1, l1 = 1, lc1 = 0.5, lc2 = 1, Ic1 = 0.083, Ic2 = 0.33, b = 0.1,
               g = 9.81;
  const double I1 = Ic1 + m1 * lc1 * lc1, I2 = Ic2 + m2 * lc2 * lc2;
  const double c2 = std::cos(q[1]), s1 = std::sin(q[0]), s2 = std::sin(q[1]),
               s12 = std::sin(q[0] + q[1]);
  Eigen::Matrix2d M, C;
  M << I1 + I2 + m2 * l1 * l1 + 2 * m2 * l1 * lc2 * c2, I2 + m2 * l1 * lc2 * c2,
      I2 + m2 * l1 * lc2 * c2, I2;
  C << -2 * m2 * l1 * lc2 * s2 * qd[1], -m2 * l1 * lc2 * s2 * qd[1], m2 * l1 * lc2 * s2 * qd[0], 0;
  const Eigen::Vector2d tau_g(-m1 * g * lc1 * s1 - m2 * g * (l1 * s1 + lc2 * s12),
                              -m2 * g * lc2 * s12);
  return M * qdd + C * qd - tau_g + b * qd;
}

class AcrobotTest : public ::testing::Test {
 protected:
  Model model = Model::from_urdf_file(testing::robot_path("acrobot/acrobot.urdf"));
  Data data{model};
};

TEST_F(AcrobotTest, ModelStructure) {
  ASSERT_EQ(model.nq(), 2);
  EXPECT_EQ(model.bodies[0].joint_name, "shoulder");
  EXPECT_EQ(model.bodies[1].joint_name, "elbow");
  // URDF cannot mark the shoulder passive (its effort="0" reads as unknown): scenes declare it.
  EXPECT_TRUE(model.bodies[0].actuated);
  EXPECT_TRUE(std::isinf(model.bodies[0].limits.effort));
  EXPECT_TRUE(model.bodies[1].actuated);
  EXPECT_DOUBLE_EQ(model.bodies[0].damping, 0.1);
  EXPECT_DOUBLE_EQ(model.bodies[1].damping, 0.1);
  EXPECT_NEAR(model.total_mass(), 2.0, 1e-12);
}

TEST_F(AcrobotTest, ReferenceVectors) {
  struct Case {
    Eigen::Vector2d q, qd, qdd, tau;
  };
  const Case cases[] = {
      {{0.3, -0.7}, {0.5, 1.2}, {0.1, -0.4}, {1.860452, -4.183764}},
      {{1.0, 0.5}, {-2, 3}, {1.5, -0.5}, {28.929404, 14.649502}},
      {{M_PI / 2, 0}, {0, 0}, {0, 0}, {24.525, 9.81}},
      {{0, 0}, {0, 0}, {0, 0}, {0, 0}},
      {{M_PI, 0}, {0, 0}, {0, 0}, {0, 0}},
  };
  for (const Case& c : cases) {
    const Eigen::VectorXd tau = rnea(model, data, c.q, c.qd, c.qdd);
    EXPECT_NEAR(tau[0], c.tau[0], 1e-6) << c.q.transpose();
    EXPECT_NEAR(tau[1], c.tau[1], 1e-6) << c.q.transpose();
  }
}

TEST_F(AcrobotTest, MassMatrixAtStraightElbow) {
  Eigen::Matrix2d expected;
  expected << 4.663, 2.33, 2.33, 1.33;
  const Eigen::Vector2d q(0.7, 0.0);
  EXPECT_TRUE(mass_matrix(model, data, q).isApprox(expected, 1e-12));
}

TEST_F(AcrobotTest, RandomStatesMatchClosedForm) {
  std::mt19937 rng(7);
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector2d q = testing::random_vector(rng, 2, M_PI);
    const Eigen::Vector2d qd = testing::random_vector(rng, 2, 5);
    const Eigen::Vector2d qdd = testing::random_vector(rng, 2, 10);
    const Eigen::Vector2d expected = closed_form(q, qd, qdd);
    EXPECT_TRUE(rnea(model, data, q, qd, qdd).isApprox(expected, 1e-10))
        << data.tau.transpose() << " vs " << expected.transpose();
    rnea_derivatives(model, data, q, qd, qdd);
    EXPECT_TRUE(data.tau.isApprox(expected, 1e-10));
  }
}

}  // namespace
}  // namespace kinograph::dynamics

// Analytic derivatives of RNEA against central differences, mass matrix against the linearity
// of τ in q̈, forward dynamics against inverse dynamics, Jacobians against differentiated FK.
// Run on the iiwa14 with a payload and an external wrench, and on a branching test tree with
// prismatic, continuous and merged fixed joints.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <random>
#include <vector>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/dynamics/payload.h"
#include "test_util.h"

namespace kinograph::dynamics {
namespace {

struct Robot {
  std::string label;
  Model model;
  std::vector<ExternalWrench> ext;
};

std::vector<Robot> robots() {
  std::vector<Robot> out;
  const Model iiwa = Model::from_urdf_file(testing::robot_path("iiwa14/iiwa14.urdf"));
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  offset.translation() << 0.01, -0.02, 0.03;
  out.push_back({"iiwa14", iiwa, {}});
  Vector6 w;
  w << 0.3, -0.2, 0.5, 4.0, -2.0, 7.0;
  out.push_back({"iiwa14+payload+wrench",
                 attach_box_payload(iiwa, "iiwa_link_ee_kuka", 3.0, {0.1, 0.05, 0.08}, offset),
                 {{6, w}, {3, -0.5 * w}}});
  const Model tree = Model::from_urdf_string(testing::kTreeUrdf);
  out.push_back({"tree", tree, {}});
  out.push_back({"tree+wrench", tree, {{2, w}, {5, 0.3 * w}, {1, -w}}});
  return out;
}

double relative_error(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(1.0, b.norm());
}

TEST(Derivatives, MatchCentralDifferences) {
  std::mt19937 rng(11);
  const double h = 1e-6;
  for (Robot& r : robots()) {
    const Model& m = r.model;
    const int n = m.nq();
    Data data(m), scratch(m);
    for (int k = 0; k < 20; ++k) {
      const Eigen::VectorXd q = testing::random_vector(rng, n, 2.5);
      const Eigen::VectorXd qd = testing::random_vector(rng, n, 3.0);
      const Eigen::VectorXd qdd = testing::random_vector(rng, n, 5.0);
      rnea_derivatives(m, data, q, qd, qdd, r.ext);
      Eigen::MatrixXd fd_q(n, n), fd_qd(n, n);
      for (int j = 0; j < n; ++j) {
        Eigen::VectorXd qp = q, qm = q, vp = qd, vm = qd;
        qp[j] += h;
        qm[j] -= h;
        vp[j] += h;
        vm[j] -= h;
        const Eigen::VectorXd tp = rnea(m, scratch, qp, qd, qdd, r.ext);
        fd_q.col(j) = (tp - rnea(m, scratch, qm, qd, qdd, r.ext)) / (2 * h);
        const Eigen::VectorXd up = rnea(m, scratch, q, vp, qdd, r.ext);
        fd_qd.col(j) = (up - rnea(m, scratch, q, vm, qdd, r.ext)) / (2 * h);
      }
      EXPECT_LT(relative_error(data.dtau_dq, fd_q), 1e-6) << r.label << "\n"
                                                          << data.dtau_dq << "\n\n"
                                                          << fd_q;
      EXPECT_LT(relative_error(data.dtau_dqd, fd_qd), 1e-6) << r.label << "\n"
                                                            << data.dtau_dqd << "\n\n"
                                                            << fd_qd;
    }
  }
}

TEST(Derivatives, DerivativePassAgreesWithRnea) {
  std::mt19937 rng(12);
  for (Robot& r : robots()) {
    const Model& m = r.model;
    const int n = m.nq();
    Data a(m), b(m);
    for (int k = 0; k < 10; ++k) {
      const Eigen::VectorXd q = testing::random_vector(rng, n, 3.0);
      const Eigen::VectorXd qd = testing::random_vector(rng, n, 3.0);
      const Eigen::VectorXd qdd = testing::random_vector(rng, n, 5.0);
      rnea(m, a, q, qd, qdd, r.ext);
      rnea_derivatives(m, b, q, qd, qdd, r.ext);
      EXPECT_TRUE(a.tau.isApprox(b.tau, 1e-10)) << r.label;
      for (int i = 0; i < n; ++i) {
        EXPECT_TRUE(a.V[i].isApprox(b.V[i], 1e-10)) << r.label << " body " << i;
        EXPECT_TRUE(a.Vdot[i].isApprox(b.Vdot[i], 1e-10)) << r.label << " body " << i;
        EXPECT_TRUE(a.F[i].isApprox(b.F[i], 1e-10)) << r.label << " body " << i;
        EXPECT_TRUE(a.body_pose[i].isApprox(b.body_pose[i], 1e-12));
      }
    }
  }
}

TEST(Derivatives, MassMatrixIsDerivativeInAcceleration) {
  // τ is affine in q̈, so column j of M is exactly τ(e_j) − τ(0).
  std::mt19937 rng(13);
  for (Robot& r : robots()) {
    const Model& m = r.model;
    const int n = m.nq();
    Data data(m), scratch(m);
    for (int k = 0; k < 10; ++k) {
      const Eigen::VectorXd q = testing::random_vector(rng, n, 3.0);
      const Eigen::VectorXd qd = testing::random_vector(rng, n, 3.0);
      Eigen::MatrixXd fd(n, n);
      const Eigen::VectorXd tau0 = rnea(m, scratch, q, qd, Eigen::VectorXd::Zero(n), r.ext);
      for (int j = 0; j < n; ++j) {
        fd.col(j) = rnea(m, scratch, q, qd, Eigen::VectorXd::Unit(n, j), r.ext) - tau0;
      }
      EXPECT_LT(relative_error(mass_matrix(m, data, q), fd), 1e-10) << r.label;
      rnea_derivatives(m, data, q, qd, Eigen::VectorXd::Zero(n), r.ext);
      EXPECT_LT(relative_error(data.M, fd), 1e-10) << r.label;
      EXPECT_TRUE(data.M.isApprox(data.M.transpose(), 1e-14));
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(data.M).eigenvalues().minCoeff(),
                0.0);
    }
  }
}

TEST(Derivatives, ForwardDynamicsInvertsInverseDynamics) {
  std::mt19937 rng(14);
  for (Robot& r : robots()) {
    const Model& m = r.model;
    const int n = m.nq();
    Data data(m);
    for (int k = 0; k < 20; ++k) {
      const Eigen::VectorXd q = testing::random_vector(rng, n, 3.0);
      const Eigen::VectorXd qd = testing::random_vector(rng, n, 3.0);
      const Eigen::VectorXd qdd = testing::random_vector(rng, n, 5.0);
      const Eigen::VectorXd tau = rnea(m, data, q, qd, qdd, r.ext);
      EXPECT_TRUE(forward_dynamics(m, data, q, qd, tau, r.ext).isApprox(qdd, 1e-8)) << r.label;
      // Aliasing data.tau as the input torque is allowed.
      rnea(m, data, q, qd, qdd, r.ext);
      EXPECT_TRUE(forward_dynamics(m, data, q, qd, data.tau, r.ext).isApprox(qdd, 1e-8));
    }
  }
}

TEST(Derivatives, PassiveDynamicsZeroesThePassiveTorques) {
  std::mt19937 rng(16);
  for (Robot& r : robots()) {
    const Model& m = r.model;
    const int n = m.nq();
    Data data(m), reference(m);
    const std::vector<std::vector<int>> sets = {{0}, {1, n - 1}, {n - 2}};
    for (const std::vector<int>& passive : sets) {
      for (int k = 0; k < 10; ++k) {
        const Eigen::VectorXd q = testing::random_vector(rng, n, 3.0);
        const Eigen::VectorXd qd = testing::random_vector(rng, n, 3.0);
        const Eigen::VectorXd qdd = testing::random_vector(rng, n, 5.0);
        for (const bool derivatives : {false, true}) {
          passive_dynamics(m, data, q, qd, qdd, passive, derivatives, r.ext);
          const Eigen::VectorXd out = data.qdd;
          for (int j = 0; j < n; ++j) {
            const bool is_passive = std::find(passive.begin(), passive.end(), j) != passive.end();
            if (is_passive) {
              EXPECT_NEAR(data.tau[j], 0.0, 1e-9) << r.label << " joint " << j;
            } else {
              EXPECT_EQ(out[j], qdd[j]) << r.label << " joint " << j;
            }
          }
          // The same torques, mass matrix and derivatives as the separate algorithms at that q̈.
          EXPECT_LT(relative_error(data.tau, rnea(m, reference, q, qd, out, r.ext)), 1e-10);
          EXPECT_LT(relative_error(data.M, mass_matrix(m, reference, q)), 1e-12);
          if (!derivatives) continue;
          rnea_derivatives(m, reference, q, qd, out, r.ext);
          EXPECT_LT(relative_error(data.dtau_dq, reference.dtau_dq), 1e-10) << r.label;
          EXPECT_LT(relative_error(data.dtau_dqd, reference.dtau_dqd), 1e-10) << r.label;
        }
      }
    }
    // Every joint passive: forward dynamics with zero torque.
    std::vector<int> all(n);
    for (int j = 0; j < n; ++j) all[j] = j;
    const Eigen::VectorXd q = testing::random_vector(rng, n, 3.0);
    const Eigen::VectorXd qd = testing::random_vector(rng, n, 3.0);
    passive_dynamics(m, data, q, qd, Eigen::VectorXd::Zero(n), all, false, r.ext);
    EXPECT_TRUE(data.qdd.isApprox(
        forward_dynamics(m, reference, q, qd, Eigen::VectorXd::Zero(n), r.ext), 1e-8))
        << r.label;
  }
}

TEST(Kinematics, JacobiansMatchDifferentiatedPoses) {
  std::mt19937 rng(15);
  const double h = 1e-6;
  for (Robot& r : robots()) {
    const Model& m = r.model;
    const int n = m.nq();
    Data data(m), dp(m), dm(m);
    Eigen::Matrix<double, 6, Eigen::Dynamic> J(6, n);
    Eigen::Matrix3Xd Jp(3, n);
    for (int k = 0; k < 5; ++k) {
      const Eigen::VectorXd q = testing::random_vector(rng, n, 3.0);
      forward_kinematics(m, data, q);
      for (int b = 0; b < n; ++b) {
        space_jacobian(m, data, b, J);
        const Eigen::Vector3d p = data.body_pose[b] * Eigen::Vector3d(0.1, -0.2, 0.3);
        point_jacobian(m, data, b, p, Jp);
        for (int j = 0; j < n; ++j) {
          Eigen::VectorXd qp = q, qm = q;
          qp[j] += h;
          qm[j] -= h;
          forward_kinematics(m, dp, qp);
          forward_kinematics(m, dm, qm);
          // Spatial twist of the motion: log(T(q+h) T(q−h)^{-1}) / 2h.
          const Vector6 fd = log_se3(dp.body_pose[b] * dm.body_pose[b].inverse()) / (2 * h);
          EXPECT_TRUE((J.col(j) - fd).norm() < 1e-7) << r.label << " body " << b << " q" << j;
          const Eigen::Vector3d v = (dp.body_pose[b] * Eigen::Vector3d(0.1, -0.2, 0.3) -
                                     dm.body_pose[b] * Eigen::Vector3d(0.1, -0.2, 0.3)) /
                                    (2 * h);
          EXPECT_TRUE((Jp.col(j) - v).norm() < 1e-7) << r.label << " body " << b << " q" << j;
        }
      }
    }
  }
}

TEST(Dynamics, EnergyBalance) {
  // Power balance, independent of the recursion's bookkeeping: with τ = RNEA(q, q̇, q̈) and no
  // external wrench, d/dt (kinetic + potential energy) = q̇ᵀ(τ − b ⊙ q̇). Kinetic energy is
  // ½ Σ V_iᵀ G_i V_i from body twists and potential energy −Σ m_i gᵀ c_i from COM positions.
  std::mt19937 rng(16);
  for (Robot& r : robots()) {
    if (!r.ext.empty()) continue;
    const Model& m = r.model;
    const int n = m.nq();
    Data data(m);
    auto energy = [&](const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
      rnea(m, data, q, qd, Eigen::VectorXd::Zero(n));
      double e = 0;
      for (int i = 0; i < n; ++i) {
        const Matrix6& G = m.bodies[i].inertia;
        e += 0.5 * data.V[i].dot(G * data.V[i]);
        const double mass = G(3, 3);
        const Eigen::Matrix3d mc = G.topRightCorner<3, 3>();
        const Eigen::Vector3d c_body(mc(2, 1), mc(0, 2), mc(1, 0));
        e -= m.gravity.dot(data.body_pose[i] * (c_body / mass)) * mass;
      }
      return e;
    };
    for (int k = 0; k < 10; ++k) {
      const Eigen::VectorXd q = testing::random_vector(rng, n, 2.0);
      const Eigen::VectorXd qd = testing::random_vector(rng, n, 2.0);
      const Eigen::VectorXd qdd = testing::random_vector(rng, n, 3.0);
      const double dt = 1e-5;
      const double dE = (energy(q + dt * qd + 0.5 * dt * dt * qdd, qd + dt * qdd) -
                         energy(q - dt * qd + 0.5 * dt * dt * qdd, qd - dt * qdd)) /
                        (2 * dt);
      Eigen::VectorXd damping(n);
      for (int i = 0; i < n; ++i) damping[i] = m.bodies[i].damping;
      const Eigen::VectorXd tau = rnea(m, data, q, qd, qdd);
      const double power = qd.dot(tau - damping.cwiseProduct(qd));
      EXPECT_NEAR(dE, power, 1e-5 * std::max(1.0, std::abs(power))) << r.label;
    }
  }
}

}  // namespace
}  // namespace kinograph::dynamics

#pragma once
// A planning-shaped test problem for the graph benchmark: T steps, per step four 7-vectors
// (q, q̇, q̈, τ), a constant-acceleration GP prior between steps (full 21×21 covariance), a
// nonlinear "dynamics" factor per step, hinge limits on q and τ, start and goal priors. It has
// the block-banded structure of the planner's graphs without depending on robot code.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "kinograph/graph/factor_graph.h"
#include "kinograph/graph/noise_model.h"
#include "kinograph/graph/prior_factor.h"
#include "kinograph/graph/values.h"
#include "tests/graph/problems.h"

namespace kinograph::graph::bench {

/// e = [q; q̇; q̈]_{k+1} − Φ(Δt)·[q; q̇; q̈]_k (linear, whitened by the GP's Q).
class GpPriorFactor final : public Factor {
 public:
  GpPriorFactor(int n, int k, double dt, NoiseModelPtr noise)
      : Factor({Key('q', 0, k), Key('v', 0, k), Key('a', 0, k), Key('q', 0, k + 1),
                Key('v', 0, k + 1), Key('a', 0, k + 1)},
               {n, n, n, n, n, n}, 3 * n, std::move(noise)),
        n_(n),
        dt_(dt) {}
  void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const Jacobians* J) const override {
    const double h = dt_;
    const int kDof = n_;
    e.segment(0, kDof) = x[3] - x[0] - h * x[1] - 0.5 * h * h * x[2];
    e.segment(kDof, kDof) = x[4] - x[1] - h * x[2];
    e.segment(2 * kDof, kDof) = x[5] - x[2];
    if (J) {
      const auto I = Eigen::MatrixXd::Identity(kDof, kDof);
      J->block(0).topRows(kDof) = -I;
      J->block(1).topRows(kDof) = -h * I;
      J->block(1).middleRows(kDof, kDof) = -I;
      J->block(2).topRows(kDof) = -0.5 * h * h * I;
      J->block(2).middleRows(kDof, kDof) = -h * I;
      J->block(2).bottomRows(kDof) = -I;
      J->block(3).topRows(kDof) = I;
      J->block(4).middleRows(kDof, kDof) = I;
      J->block(5).bottomRows(kDof) = I;
    }
  }
  /// Covariance of the constant-acceleration (white jerk) GP over one step, Qc = qc·I.
  static Eigen::MatrixXd covariance(int kDof, double dt, double qc) {
    Eigen::Matrix3d Q1;
    const double h = dt;
    Q1 << std::pow(h, 5) / 20, std::pow(h, 4) / 8, std::pow(h, 3) / 6, std::pow(h, 4) / 8,
        std::pow(h, 3) / 3, h * h / 2, std::pow(h, 3) / 6, h * h / 2, h;
    Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(3 * kDof, 3 * kDof);
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        Q.block(i * kDof, j * kDof, kDof, kDof) =
            qc * Q1(i, j) * Eigen::MatrixXd::Identity(kDof, kDof);
      }
    }
    return Q;
  }

 private:
  int n_;
  double dt_;
};

/// Toy inverse dynamics: e = τ − (M q̈ + b ⊙ sin q + c ⊙ q̇ ⊙ q̇), M fixed SPD and dense.
class ToyDynamicsFactor final : public Factor {
 public:
  ToyDynamicsFactor(int k, const Eigen::MatrixXd& M, const Eigen::VectorXd& b,
                    const Eigen::VectorXd& c, NoiseModelPtr noise)
      : Factor({Key('q', 0, k), Key('v', 0, k), Key('a', 0, k), Key('t', 0, k)},
               std::vector<int>(4, static_cast<int>(b.size())), static_cast<int>(b.size()),
               std::move(noise)),
        M_(M),
        b_(b),
        c_(c) {}
  void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const Jacobians* J) const override {
    const auto q = x[0], v = x[1], a = x[2], tau = x[3];
    e.noalias() = tau - M_ * a;
    e.array() -= b_.array() * q.array().sin() + c_.array() * v.array().square();
    if (J) {
      J->block(0).diagonal() = -(b_.array() * q.array().cos()).matrix();
      J->block(1).diagonal() = -(2.0 * c_.array() * v.array()).matrix();
      J->block(2) = -M_;
      J->block(3).setIdentity();
    }
  }

 private:
  Eigen::MatrixXd M_;
  Eigen::VectorXd b_, c_;
};

/// The hinge limit as the planner would use it: z = x itself under HingeNoise.
class LimitFactor final : public Factor {
 public:
  LimitFactor(Key key, const NoiseModelPtr& hinge)
      : Factor({key}, {hinge->dim()}, hinge->dim(), hinge) {}
  void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const Jacobians* J) const override {
    e = x[0];
    if (J) J->block(0).setIdentity();
  }
};

/// T steps of an n-DoF swing from 0 to 1.2 rad on every joint in T·dt seconds, started from the
/// straight line with zero torque (T + 1 time points, 4 variables of dimension n each).
inline problems::Problem planning_problem(int steps, int kDof = 7, unsigned seed = 3) {
  problems::Problem p;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0.5, 1.5);
  const double dt = 0.02;
  Eigen::MatrixXd A(kDof, kDof);
  for (int i = 0; i < kDof * kDof; ++i) A(i / kDof, i % kDof) = U(rng) - 1.0;
  const Eigen::MatrixXd M = A * A.transpose() + Eigen::MatrixXd::Identity(kDof, kDof);
  Eigen::VectorXd b(kDof), c(kDof);
  for (int i = 0; i < kDof; ++i) {
    b[i] = 5.0 * U(rng);
    c[i] = 0.3 * U(rng);
  }
  const auto gp_noise = gaussian_covariance(GpPriorFactor::covariance(kDof, dt, 1.0));
  const auto dyn_noise = isotropic(kDof, 0.01);
  const auto tau_small = isotropic(kDof, 10.0);  // minimum torque
  const double inf = std::numeric_limits<double>::infinity();
  const auto q_limit = hinge(Eigen::VectorXd::Constant(kDof, -1.0),
                             Eigen::VectorXd::Constant(kDof, 1.5), 0.02, 10.0);
  const auto tau_limit = hinge(Eigen::VectorXd::Constant(kDof, -20.0),
                               Eigen::VectorXd::Constant(kDof, inf), 0.5, 10.0);
  const auto pin = isotropic(kDof, 1e-3);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(kDof);
  const Eigen::VectorXd goal = Eigen::VectorXd::Constant(kDof, 1.2);
  for (int k = 0; k <= steps; ++k) {
    const double s = static_cast<double>(k) / steps;
    p.start.insert(Key('q', 0, k), goal * s);
    p.start.insert(Key('v', 0, k), goal / (steps * dt));
    p.start.insert(Key('a', 0, k), zero);
    p.start.insert(Key('t', 0, k), zero);
    if (k < steps) p.graph.emplace<GpPriorFactor>(kDof, k, dt, gp_noise);
    p.graph.emplace<ToyDynamicsFactor>(k, M, b, c, dyn_noise);
    p.graph.emplace<PriorFactor>(Key('t', 0, k), zero, tau_small);
    p.graph.emplace<LimitFactor>(Key('q', 0, k), q_limit);
    p.graph.emplace<LimitFactor>(Key('t', 0, k), tau_limit);
  }
  p.graph.emplace<PriorFactor>(Key('q', 0, 0), zero, pin);
  p.graph.emplace<PriorFactor>(Key('v', 0, 0), zero, pin);
  p.graph.emplace<PriorFactor>(Key('q', 0, steps), goal, pin);
  p.graph.emplace<PriorFactor>(Key('v', 0, steps), zero, pin);
  return p;
}

}  // namespace kinograph::graph::bench

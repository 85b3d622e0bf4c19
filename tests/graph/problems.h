#pragma once
// Nonlinear least-squares problems shared by the graph tests and the graph benchmark, and an
// adapter that lets Ceres evaluate kinograph factors, so both solvers see identical residuals.
#include <ceres/ceres.h>

#include <Eigen/Core>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "kinograph/graph/factor_graph.h"
#include "kinograph/graph/noise_model.h"
#include "kinograph/graph/prior_factor.h"
#include "kinograph/graph/values.h"

namespace kinograph::graph::problems {

/// Exponential curve fit: e = exp(m·t + c) − y for one sample, over the variable (m, c).
class ExpSampleFactor final : public Factor {
 public:
  ExpSampleFactor(Key key, double t, double y) : Factor({key}, {2}, 1), t_(t), y_(y) {}
  void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const Jacobians* J) const override {
    const auto v = x[0];
    const double f = std::exp(v[0] * t_ + v[1]);
    e[0] = f - y_;
    if (J) {
      auto b = J->block(0);
      b(0, 0) = f * t_;
      b(0, 1) = f;
    }
  }

 private:
  double t_, y_;
};

/// Nonlinear transition between neighbours of a chain of 3-vectors:
/// e = x_{k+1} − g(x_k) − u with g(x) = x + h·[sin x₁; ½cos x₀; 0.3·x₀x₁ − 0.2·x₂].
class ChainTransitionFactor final : public Factor {
 public:
  ChainTransitionFactor(Key a, Key b, const Eigen::Vector3d& u, NoiseModelPtr noise)
      : Factor({a, b}, {3, 3}, 3, std::move(noise)), u_(u) {}
  static Eigen::Vector3d g(const Eigen::Vector3d& x) {
    return x + kH * Eigen::Vector3d(std::sin(x[1]), 0.5 * std::cos(x[0]),
                                    0.3 * x[0] * x[1] - 0.2 * x[2]);
  }
  void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const Jacobians* J) const override {
    const Eigen::Vector3d xa = x[0], xb = x[1];
    e = xb - g(xa) - u_;
    if (J) {
      Eigen::Matrix3d G = Eigen::Matrix3d::Identity();
      G(0, 1) += kH * std::cos(xa[1]);
      G(1, 0) += -kH * 0.5 * std::sin(xa[0]);
      G(2, 0) += kH * 0.3 * xa[1];
      G(2, 1) += kH * 0.3 * xa[0];
      G(2, 2) += -kH * 0.2;
      J->block(0) = -G;
      J->block(1).setIdentity();
    }
  }
  static constexpr double kH = 0.1;

 private:
  Eigen::Vector3d u_;
};

/// Nonlinear measurement of one chain state: e = [√(1 + ‖x‖²); x₀ + 0.1·x₂²] − z.
class ChainMeasurementFactor final : public Factor {
 public:
  ChainMeasurementFactor(Key key, const Eigen::Vector2d& z, NoiseModelPtr noise)
      : Factor({key}, {3}, 2, std::move(noise)), z_(z) {}
  static Eigen::Vector2d h(const Eigen::Vector3d& x) {
    return {std::sqrt(1.0 + x.squaredNorm()), x[0] + 0.1 * x[2] * x[2]};
  }
  void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const Jacobians* J) const override {
    const Eigen::Vector3d v = x[0];
    e = h(v) - z_;
    if (J) {
      auto b = J->block(0);
      b.row(0) = v.transpose() / std::sqrt(1.0 + v.squaredNorm());
      b(1, 0) = 1;
      b(1, 2) = 0.2 * v[2];
    }
  }

 private:
  Eigen::Vector2d z_;
};

/// A problem: the graph, the start values, and (for synthetic data) the ground truth.
struct Problem {
  FactorGraph graph;
  Values start;
};

/// y = exp(0.3 t + 0.1) plus Gaussian noise (σ 0.2) at `samples` points in [0, 5); start (0, 0).
inline Problem curve_fit(int samples = 67, unsigned seed = 7) {
  Problem p;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.2);
  const Key key('m', 0, 0);
  for (int i = 0; i < samples; ++i) {
    const double t = 5.0 * i / samples;
    p.graph.emplace<ExpSampleFactor>(key, t, std::exp(0.3 * t + 0.1) + noise(rng));
  }
  p.start.insert(key, Eigen::Vector2d::Zero());
  return p;
}

/// A chain of `n` 3-vectors: a prior on x₀, a transition between neighbours (full covariance),
/// and a measurement at every step. Data come from a noisy simulated trajectory; the start is
/// the truth perturbed by σ = 0.3.
inline Problem chain(int n, unsigned seed = 11) {
  Problem p;
  std::mt19937 rng(seed);
  std::normal_distribution<double> N(0.0, 1.0);
  Eigen::Matrix3d cov;
  cov << 0.04, 0.01, 0.0, 0.01, 0.05, 0.005, 0.0, 0.005, 0.03;
  const auto transition_noise = gaussian_covariance(cov);
  const auto measurement_noise = diagonal(Eigen::Vector2d(0.3, 0.2));
  std::vector<Eigen::Vector3d> truth(n);
  truth[0] = Eigen::Vector3d(0.5, -0.2, 0.1);
  for (int k = 0; k + 1 < n; ++k) {
    const Eigen::Vector3d u(0.05 * std::sin(0.01 * k), 0.02, -0.01);
    truth[k + 1] =
        ChainTransitionFactor::g(truth[k]) + u + 0.05 * Eigen::Vector3d(N(rng), N(rng), N(rng));
    p.graph.emplace<ChainTransitionFactor>(Key('x', 0, k), Key('x', 0, k + 1), u, transition_noise);
  }
  p.graph.emplace<PriorFactor>(Key('x', 0, 0), truth[0], isotropic(3, 0.1));
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector2d z =
        ChainMeasurementFactor::h(truth[k]) + Eigen::Vector2d(0.3 * N(rng), 0.2 * N(rng));
    p.graph.emplace<ChainMeasurementFactor>(Key('x', 0, k), z, measurement_noise);
  }
  for (int k = 0; k < n; ++k) {
    p.start.insert(Key('x', 0, k), truth[k] + 0.3 * Eigen::Vector3d(N(rng), N(rng), N(rng)));
  }
  return p;
}

/// Ceres view of a kinograph factor: Evaluate() calls the factor's whitened residual and
/// Jacobian and copies the blocks into Ceres' row-major layout.
class FactorCost final : public ceres::CostFunction {
 public:
  explicit FactorCost(const Factor& factor) : factor_(factor) {
    set_num_residuals(factor.residual_dim());
    for (int d : factor.dims()) mutable_parameter_block_sizes()->push_back(d);
    r_.resize(factor.residual_dim());
    J_.resize(factor.residual_dim(), factor.jacobian_cols());
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    Eigen::Map<Eigen::VectorXd> r(residuals, factor_.residual_dim());
    r.setZero();
    if (jacobians == nullptr) {
      factor_.whitened(parameters, r, nullptr);
      return r.allFinite();
    }
    Eigen::Ref<Eigen::MatrixXd> J(J_);
    factor_.whitened(parameters, r, &J);
    const int m = factor_.residual_dim();
    for (size_t i = 0; i < factor_.dims().size(); ++i) {
      if (jacobians[i] == nullptr) continue;
      const int d = factor_.dims()[i];
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          jacobians[i], m, d) = J_.middleCols(factor_.block_offsets()[i], d);
    }
    return r.allFinite() && J_.allFinite();
  }

 private:
  const Factor& factor_;
  mutable Eigen::VectorXd r_;
  mutable Eigen::MatrixXd J_;
};

/// The same problem for Ceres, over a copy of the values (`params`, laid out like Values).
inline void build_ceres(const FactorGraph& graph, const Values& values, Eigen::VectorXd& params,
                        ceres::Problem& problem) {
  params = values.vector();
  for (const auto& f : graph.factors()) {
    if (!f) continue;
    std::vector<double*> blocks;
    for (Key k : f->keys()) blocks.push_back(params.data() + values.offset(values.slot(k)));
    problem.AddResidualBlock(new FactorCost(*f), nullptr, blocks);
  }
  for (int s = 0; s < values.size(); ++s) {
    if (values.is_fixed_slot(s))
      problem.SetParameterBlockConstant(params.data() + values.offset(s));
  }
}

/// Ceres options matching LevenbergMarquardtOptions' defaults: LM, sparse normal Cholesky with
/// SuiteSparse, initial trust radius 1/λ₀, stop on relative cost decrease only.
inline ceres::Solver::Options ceres_options(double relative_tol = 1e-5, double step_tol = 1e-14,
                                            double lambda0 = 0.01) {
  ceres::Solver::Options o;
  o.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  o.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  o.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  o.initial_trust_region_radius = 1.0 / lambda0;
  o.max_num_iterations = 200;
  o.function_tolerance = relative_tol;
  o.gradient_tolerance = 0;
  o.parameter_tolerance = step_tol;
  o.num_threads = 1;
  o.logging_type = ceres::SILENT;
  o.minimizer_progress_to_stdout = false;
  return o;
}

}  // namespace kinograph::graph::problems

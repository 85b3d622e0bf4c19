// Linear least squares: the sparse normal-equation solvers against a dense QR solve of the
// stacked, whitened system built independently from each factor's A, b and noise.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/QR>
#include <random>

#include "kinograph/graph/gauss_newton.h"
#include "kinograph/graph/levenberg_marquardt.h"
#include "kinograph/graph/linear_factor.h"
#include "kinograph/graph/normal_equations.h"

namespace kinograph::graph {
namespace {

struct LinearProblem {
  FactorGraph graph;
  Values values;      // all zero
  Eigen::MatrixXd A;  // whitened, dense, columns laid out like values.vector()
  Eigen::VectorXd b;
};

// Random sparse linear problem: a chain of unary and binary/ternary factors over variables of
// dimension 1–4, with isotropic, diagonal and full-covariance noise.
LinearProblem random_linear(int num_vars, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> N;
  std::uniform_int_distribution<int> dim_dist(1, 4);
  LinearProblem p;
  std::vector<int> dims;
  for (int i = 0; i < num_vars; ++i) {
    dims.push_back(dim_dist(rng));
    p.values.insert(Key('x', 0, i), Eigen::VectorXd::Zero(dims.back()));
  }
  std::vector<Eigen::MatrixXd> row_blocks;
  std::vector<Eigen::VectorXd> rhs;
  auto random = [&](int r, int c) {
    Eigen::MatrixXd M(r, c);
    for (int i = 0; i < r * c; ++i) M(i % r, i / r) = N(rng);
    return M;
  };
  auto add = [&](std::vector<int> vars, int rows, int noise_kind) {
    std::vector<Key> keys;
    std::vector<Eigen::MatrixXd> A;
    for (int v : vars) {
      keys.push_back(Key('x', 0, v));
      A.push_back(random(rows, dims[v]));
    }
    const Eigen::VectorXd b = random(rows, 1);
    NoiseModelPtr noise;
    Eigen::MatrixXd W = Eigen::MatrixXd::Identity(rows, rows);
    if (noise_kind == 1) {
      noise = isotropic(rows, 0.5);
      W *= 2.0;
    } else if (noise_kind == 2) {
      const Eigen::VectorXd s = random(rows, 1).cwiseAbs().array() + 0.2;
      noise = diagonal(s);
      W = s.cwiseInverse().asDiagonal();
    } else if (noise_kind == 3) {
      const Eigen::MatrixXd L = random(rows, rows);
      const Eigen::MatrixXd cov = L * L.transpose() + 0.3 * Eigen::MatrixXd::Identity(rows, rows);
      noise = gaussian_covariance(cov);
      // Any W with WᵀW = Σ⁻¹ gives the same least-squares problem.
      W = Eigen::MatrixXd(cov.inverse().llt().matrixL()).transpose();
    }
    Eigen::MatrixXd row = Eigen::MatrixXd::Zero(rows, p.values.total_dim());
    for (size_t k = 0; k < vars.size(); ++k) {
      row.middleCols(p.values.offset(vars[k]), dims[vars[k]]) = W * A[k];
    }
    row_blocks.push_back(row);
    rhs.push_back(W * b);
    p.graph.add(std::make_shared<LinearFactor>(keys, A, b, noise));
  };
  for (int i = 0; i < num_vars; ++i) {
    add({i}, dims[i], i % 4);
    if (i + 1 < num_vars) add({i, i + 1}, 3, (i + 1) % 4);
    if (i + 3 < num_vars && i % 2 == 0) add({i, i + 1, i + 3}, 4, (i + 2) % 4);
    // Keys listed against the natural order: JᵀJ's blocks land mirrored in H.
    if (i + 2 < num_vars && i % 3 == 0) add({i + 2, i + 1}, 3, i % 4);
  }
  int rows = 0;
  for (const auto& r : row_blocks) rows += static_cast<int>(r.rows());
  p.A.resize(rows, p.values.total_dim());
  p.b.resize(rows);
  rows = 0;
  for (size_t i = 0; i < row_blocks.size(); ++i) {
    p.A.middleRows(rows, row_blocks[i].rows()) = row_blocks[i];
    p.b.segment(rows, rhs[i].size()) = rhs[i];
    rows += static_cast<int>(row_blocks[i].rows());
  }
  return p;
}

TEST(LinearSolve, GaussNewtonEqualsDenseQrForEveryOrderingAndFactorization) {
  auto p = random_linear(60, 1);
  const Eigen::VectorXd expected = p.A.colPivHouseholderQr().solve(p.b);
  for (auto ordering : {OrderingMethod::kNatural, OrderingMethod::kAmd, OrderingMethod::kColamd,
                        OrderingMethod::kMetis}) {
    for (auto fact :
         {Factorization::kAuto, Factorization::kSupernodal, Factorization::kSimplicial}) {
      Values v = p.values;
      GaussNewtonOptions o;
      o.ordering = ordering;
      o.factorization = fact;
      const auto result = GaussNewton(o).optimize(p.graph, v);
      EXPECT_TRUE(result.converged()) << result.reason;
      EXPECT_LE(result.iterations, 2);
      EXPECT_LT((v.vector() - expected).norm(), 1e-10 * expected.norm())
          << to_string(ordering) << " " << to_string(fact);
    }
  }
}

TEST(LinearSolve, LevenbergMarquardtEqualsDenseQr) {
  auto p = random_linear(80, 2);
  const Eigen::VectorXd expected = p.A.colPivHouseholderQr().solve(p.b);
  for (auto fact : {Factorization::kAuto, Factorization::kSimplicial, Factorization::kEnvelope})
  for (auto damping : {Damping::kDiagonal, Damping::kIdentity}) {
    Values v = p.values;
    LevenbergMarquardtOptions o;
    o.damping = damping;
    o.factorization = fact;
    o.relative_error_tol = 0;  // run to the step tolerance
    o.step_tol = 1e-13;
    LevenbergMarquardt lm(o);
    const auto result = lm.optimize(p.graph, v);
    // The chain is banded in slot order, so kAuto takes the envelope too.
    EXPECT_EQ(lm.uses_envelope(), fact != Factorization::kSimplicial) << to_string(fact);
    EXPECT_TRUE(result.converged()) << result.reason;
    EXPECT_LT((v.vector() - expected).norm(), 1e-10 * expected.norm());
    EXPECT_NEAR(result.final_error, 0.5 * (p.A * expected - p.b).squaredNorm(),
                1e-12 * result.final_error);
  }
}

TEST(LinearSolve, FixedVariablesStayAndTheRestSolvesTheReducedProblem) {
  auto p = random_linear(30, 3);
  std::mt19937 rng(5);
  std::normal_distribution<double> N;
  // Fix variables 0, 7 and 29 at random values.
  std::vector<int> fixed = {0, 7, 29};
  Eigen::VectorXd x_fixed = Eigen::VectorXd::Zero(p.values.total_dim());
  std::vector<int> free_cols;
  for (int s = 0; s < p.values.size(); ++s) {
    const bool is_fixed = std::find(fixed.begin(), fixed.end(), s) != fixed.end();
    for (int k = 0; k < p.values.dim(s); ++k) {
      if (is_fixed) {
        x_fixed[p.values.offset(s) + k] = N(rng);
      } else {
        free_cols.push_back(p.values.offset(s) + k);
      }
    }
    if (is_fixed) {
      p.values.update(p.values.key(s), x_fixed.segment(p.values.offset(s), p.values.dim(s)));
      p.values.set_fixed(p.values.key(s));
    }
  }
  Eigen::MatrixXd A_free(p.A.rows(), free_cols.size());
  for (size_t c = 0; c < free_cols.size(); ++c) A_free.col(c) = p.A.col(free_cols[c]);
  const Eigen::VectorXd y = A_free.colPivHouseholderQr().solve(p.b - p.A * x_fixed);

  const Eigen::VectorXd before = p.values.vector();
  LevenbergMarquardtOptions o;
  o.relative_error_tol = 0;
  o.step_tol = 1e-13;
  const auto result = LevenbergMarquardt(o).optimize(p.graph, p.values);
  EXPECT_TRUE(result.converged()) << result.reason;
  for (int s : fixed) {
    for (int k = 0; k < p.values.dim(s); ++k) {
      EXPECT_EQ(p.values.vector()[p.values.offset(s) + k], before[p.values.offset(s) + k]);
    }
  }
  for (size_t c = 0; c < free_cols.size(); ++c) {
    EXPECT_NEAR(p.values.vector()[free_cols[c]], y[c], 1e-10 * y.norm());
  }
}

// In natural order a factor's blocks are merged into runs down H's columns (and along JᵀJ's rows
// for keys listed against that order); in AMD's order most are not.
class AssembledSystem : public ::testing::TestWithParam<OrderingMethod> {};

TEST_P(AssembledSystem, EqualsDenseJtJ) {
  auto p = random_linear(25, 4);
  std::mt19937 rng(9);
  std::normal_distribution<double> N;
  for (int i = 0; i < p.values.total_dim(); ++i) p.values.vector()[i] = N(rng);
  p.values.set_fixed(Key('x', 0, 3));
  NormalEquations eq(p.graph, p.values, GetParam());
  double error = 0;
  std::string reason;
  ASSERT_TRUE(eq.linearize(p.graph, p.values, &error, &reason));
  // Dense reference over the free columns, in the solver's elimination order.
  std::vector<int> cols;
  for (int s : eq.elimination_slots()) {
    for (int k = 0; k < p.values.dim(s); ++k) cols.push_back(p.values.offset(s) + k);
  }
  ASSERT_EQ(static_cast<int>(cols.size()), eq.dim());
  Eigen::MatrixXd J(p.A.rows(), cols.size());
  for (size_t c = 0; c < cols.size(); ++c) J.col(c) = p.A.col(cols[c]);
  const Eigen::VectorXd r = p.A * p.values.vector() - p.b;
  EXPECT_NEAR(error, 0.5 * r.squaredNorm(), 1e-10 * error);
  EXPECT_LT((eq.gradient() - J.transpose() * r).norm(), 1e-10 * (J.transpose() * r).norm());
  const Eigen::MatrixXd H = J.transpose() * J;
  Eigen::VectorXd v(eq.dim()), Hv(eq.dim());
  for (int trial = 0; trial < 3; ++trial) {
    for (int i = 0; i < eq.dim(); ++i) v[i] = N(rng);
    eq.multiply(v, Hv);
    EXPECT_LT((Hv - H * v).norm(), 1e-10 * (H * v).norm());
  }
}

INSTANTIATE_TEST_SUITE_P(NormalEquations, AssembledSystem,
                         ::testing::Values(OrderingMethod::kNatural, OrderingMethod::kAmd),
                         [](const auto& info) { return to_string(info.param); });

}  // namespace
}  // namespace kinograph::graph

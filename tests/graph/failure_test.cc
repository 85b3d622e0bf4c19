// Every failure status of the batch solvers, each provoked on purpose, with its reason.
#include <gtest/gtest.h>

#include "kinograph/graph/gauss_newton.h"
#include "kinograph/graph/levenberg_marquardt.h"
#include "kinograph/graph/linear_factor.h"
#include "kinograph/graph/prior_factor.h"
#include "tests/graph/problems.h"

namespace kinograph::graph {
namespace {

// e = sqrt(x) − 1: a NaN residual for x < 0; optionally a NaN only in the Jacobian.
class SqrtFactor final : public Factor {
 public:
  SqrtFactor(Key key, bool nan_jacobian) : Factor({key}, {1}, 1), nan_jacobian_(nan_jacobian) {}
  void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const Jacobians* J) const override {
    e[0] = std::sqrt(x[0][0]) - 1;
    if (J) J->block(0)(0, 0) = nan_jacobian_ ? std::nan("") : 0.5 / std::sqrt(x[0][0]);
  }
  std::string name() const override { return "SqrtFactor"; }

 private:
  bool nan_jacobian_;
};

// e = x² − 4 with the Jacobian's sign flipped: every step goes uphill.
class WrongSignFactor final : public Factor {
 public:
  explicit WrongSignFactor(Key key) : Factor({key}, {1}, 1) {}
  void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const Jacobians* J) const override {
    e[0] = x[0][0] * x[0][0] - 4;
    if (J) J->block(0)(0, 0) = -2 * x[0][0];
  }
};

Values scalar(Key key, double v) {
  Values values;
  values.insert(key, Eigen::VectorXd::Constant(1, v));
  return values;
}

TEST(Failure, NonFiniteResidualNamesTheFactor) {
  FactorGraph g;
  const Key x('x', 0, 0);
  g.emplace<PriorFactor>(x, Eigen::VectorXd::Constant(1, 1.0));
  g.emplace<SqrtFactor>(x, false);
  Values v = scalar(x, -1.0);
  const auto r = LevenbergMarquardt().optimize(g, v);
  EXPECT_EQ(r.status, SolverStatus::kNonFinite);
  EXPECT_NE(r.reason.find("factor 1 (SqrtFactor)"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("residual"), std::string::npos) << r.reason;
  const auto gn = GaussNewton().optimize(g, v);
  EXPECT_EQ(gn.status, SolverStatus::kNonFinite);
}

TEST(Failure, NonFiniteJacobianNamesTheFactor) {
  FactorGraph g;
  const Key x('x', 0, 0);
  g.emplace<SqrtFactor>(x, true);
  Values v = scalar(x, 2.0);
  const auto r = LevenbergMarquardt().optimize(g, v);
  EXPECT_EQ(r.status, SolverStatus::kNonFinite);
  EXPECT_NE(r.reason.find("factor 0 (SqrtFactor) has a non-finite Jacobian"), std::string::npos)
      << r.reason;
  EXPECT_EQ(v.vector()[0], 2.0);
}

TEST(Failure, SingularSystemNamesTheVariable) {
  // y enters only with a zero Jacobian: H has an empty column for it.
  FactorGraph g;
  const Key x('x', 0, 0), y('y', 0, 4);
  g.add(std::make_shared<LinearFactor>(
      std::vector<Key>{x, y},
      std::vector<Eigen::MatrixXd>{Eigen::MatrixXd::Ones(1, 1), Eigen::MatrixXd::Zero(1, 1)},
      Eigen::VectorXd::Constant(1, 3.0)));
  Values v;
  v.insert(x, Eigen::VectorXd::Zero(1));
  v.insert(y, Eigen::VectorXd::Zero(1));
  const auto gn = GaussNewton().optimize(g, v);
  EXPECT_EQ(gn.status, SolverStatus::kSingular);
  EXPECT_NE(gn.reason.find("y(0,4)"), std::string::npos) << gn.reason;

  for (auto fact : {Factorization::kSimplicial, Factorization::kSupernodal}) {
    LevenbergMarquardtOptions o;
    o.min_diagonal = 0;  // without the clamp, λ·diag(H) cannot regularize the empty column
    o.factorization = fact;
    Values w = v;
    const auto lm = LevenbergMarquardt(o).optimize(g, w);
    EXPECT_EQ(lm.status, SolverStatus::kSingular) << to_string(fact);
    EXPECT_NE(lm.reason.find("y(0,4)"), std::string::npos) << lm.reason;
  }
  // With the default clamp LM regularizes it and solves for x.
  Values w = v;
  const auto lm = LevenbergMarquardt().optimize(g, w);
  EXPECT_TRUE(lm.converged()) << lm.reason;
  EXPECT_NEAR(w.at(x)[0], 3.0, 1e-6);
}

TEST(Failure, WrongJacobianGivesNoDecrease) {
  FactorGraph g;
  const Key x('x', 0, 0);
  g.emplace<WrongSignFactor>(x);
  Values v = scalar(x, 3.0);
  const auto lm = LevenbergMarquardt().optimize(g, v);
  EXPECT_EQ(lm.status, SolverStatus::kNoDecrease) << lm.reason;
  EXPECT_EQ(v.vector()[0], 3.0);  // no step was kept
  const auto gn = GaussNewton().optimize(g, v);
  EXPECT_EQ(gn.status, SolverStatus::kNoDecrease) << gn.reason;
  EXPECT_EQ(v.vector()[0], 3.0);
}

TEST(Failure, IterationLimit) {
  auto p = problems::chain(50);
  LevenbergMarquardtOptions o;
  o.max_iterations = 1;
  const auto r = LevenbergMarquardt(o).optimize(p.graph, p.start);
  EXPECT_EQ(r.status, SolverStatus::kMaxIterations) << r.reason;
  EXPECT_EQ(r.iterations, 1);
  EXPECT_LT(r.final_error, r.initial_error);
}

TEST(Failure, InconsistentInputThrowsAtTheEdge) {
  FactorGraph g;
  g.emplace<PriorFactor>(Key('x', 0, 0), Eigen::Vector2d(1, 1));
  Values missing;
  EXPECT_THROW(LevenbergMarquardt().optimize(g, missing), std::invalid_argument);
  Values wrong_dim = scalar(Key('x', 0, 0), 0.0);
  EXPECT_THROW(LevenbergMarquardt().optimize(g, wrong_dim), std::invalid_argument);
}

}  // namespace
}  // namespace kinograph::graph

// Solver behaviour on nonlinear problems: orderings and factorizations agree, structure is reused
// across solves after changing targets, fixed variables stay, statistics are consistent.
#include <gtest/gtest.h>

#include <numeric>
#include <random>

#include "kinograph/graph/levenberg_marquardt.h"
#include "kinograph/graph/linear_factor.h"
#include "kinograph/graph/normal_equations.h"
#include "kinograph/graph/ordering.h"
#include "tests/graph/problems.h"

namespace kinograph::graph {
namespace {

TEST(Solver, EveryOrderingAndFactorizationGivesTheSameSolution) {
  const auto p = problems::chain(300);
  Eigen::VectorXd reference;
  for (auto ordering : {OrderingMethod::kNatural, OrderingMethod::kAmd, OrderingMethod::kColamd,
                        OrderingMethod::kMetis}) {
    for (auto fact :
         {Factorization::kAuto, Factorization::kSupernodal, Factorization::kSimplicial}) {
      LevenbergMarquardtOptions o;
      o.ordering = ordering;
      o.factorization = fact;
      o.relative_error_tol = 0;  // stop on the step size, which pins x down
      o.step_tol = 1e-11;
      LevenbergMarquardt lm(o);
      Values v = p.start;
      const auto r = lm.optimize(p.graph, v);
      ASSERT_TRUE(r.converged()) << r.reason;
      if (fact == Factorization::kSimplicial) {
        EXPECT_FALSE(lm.cholesky()->is_supernodal());
      } else if (fact == Factorization::kSupernodal) {
        EXPECT_TRUE(lm.cholesky()->is_supernodal());
      }
      if (reference.size() == 0) {
        reference = v.vector();
      } else {
        // GN-type methods converge only linearly on a problem with non-zero residuals, and the
        // cost's rounding (1e-16 relative) limits how far x is pinned down: ~1e-7 here.
        EXPECT_LT((v.vector() - reference).cwiseAbs().maxCoeff(), 2e-6)
            << to_string(ordering) << " " << to_string(fact);
      }
    }
  }
}

TEST(Solver, OrderingsArePermutationsAndColamdHonoursGroups) {
  std::vector<std::vector<int>> factors;
  const int n = 40;
  for (int i = 0; i + 1 < n; ++i) factors.push_back({i, i + 1});
  factors.push_back({0, 20, 39});
  std::vector<int> groups(n, 0);
  groups[3] = groups[17] = 1;  // must come last
  for (auto m : {OrderingMethod::kNatural, OrderingMethod::kAmd, OrderingMethod::kColamd,
                 OrderingMethod::kMetis}) {
    auto order =
        compute_ordering(n, factors, m, m == OrderingMethod::kColamd ? groups : std::vector<int>{});
    ASSERT_EQ(static_cast<int>(order.size()), n);
    std::vector<int> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    std::vector<int> iota(n);
    std::iota(iota.begin(), iota.end(), 0);
    EXPECT_EQ(sorted, iota) << to_string(m);
    if (m == OrderingMethod::kColamd) {
      EXPECT_TRUE((order[n - 1] == 3 && order[n - 2] == 17) ||
                  (order[n - 1] == 17 && order[n - 2] == 3));
    }
  }
}

TEST(Solver, ResolveAfterChangingTargetsReusesStructure) {
  auto p = problems::chain(200);
  LevenbergMarquardtOptions o;
  o.relative_error_tol = 0;
  o.step_tol = 1e-11;
  LevenbergMarquardt lm(o);
  Values v = p.start;
  const auto first = lm.optimize(p.graph, v);
  ASSERT_TRUE(first.converged());
  EXPECT_GT(first.symbolic_s, 0.0);
  // Move the prior on x₀ and make the measurements noisier, keeping keys.
  auto prior = std::dynamic_pointer_cast<PriorFactor>(p.graph[199]);
  ASSERT_NE(prior, nullptr);
  prior->set_target(prior->target() + Eigen::Vector3d(0.3, -0.2, 0.1));
  for (size_t i = 200; i < p.graph.size(); ++i) {
    p.graph[i]->set_noise(diagonal(Eigen::Vector2d(0.6, 0.4)));
  }
  const auto second = lm.optimize(p.graph, v);
  ASSERT_TRUE(second.converged());
  EXPECT_EQ(second.symbolic_s, 0.0);  // cached structure
  Values fresh = p.start;
  const auto third = LevenbergMarquardt(o).optimize(p.graph, fresh);
  ASSERT_TRUE(third.converged());
  EXPECT_NEAR(second.final_error, third.final_error, 1e-12 * third.final_error);
  EXPECT_LT((v.vector() - fresh.vector()).cwiseAbs().maxCoeff(), 2e-6);

  // Removing a factor changes the structure: rebuilt, still right.
  p.graph.remove(5);
  Values w = v;
  const auto fourth = lm.optimize(p.graph, w);
  EXPECT_GT(fourth.symbolic_s, 0.0);
  Values w2 = v;
  const auto fifth = LevenbergMarquardt(o).optimize(p.graph, w2);
  EXPECT_NEAR(fourth.final_error, fifth.final_error, 1e-12 * fifth.final_error);
}

TEST(Solver, FixedVariablesStayFixedAndMatchCeresWithConstantBlocks) {
  auto p = problems::chain(100);
  for (int k : {0, 40, 99}) p.start.set_fixed(Key('x', 0, k));
  Values v = p.start;
  LevenbergMarquardtOptions o;
  o.relative_error_tol = 0;
  o.step_tol = 1e-11;
  const auto r = LevenbergMarquardt(o).optimize(p.graph, v);
  ASSERT_TRUE(r.converged()) << r.reason;
  for (int k : {0, 40, 99}) {
    EXPECT_EQ(v.at(Key('x', 0, k)), p.start.at(Key('x', 0, k)));
  }
  EXPECT_NE(v.at(Key('x', 0, 41)), p.start.at(Key('x', 0, 41)));
  ceres::Problem problem;
  Eigen::VectorXd params;
  problems::build_ceres(p.graph, p.start, params, problem);
  ceres::Solver::Summary summary;
  ceres::Solve(problems::ceres_options(0, 1e-11), &problem, &summary);
  EXPECT_NEAR(r.final_error, summary.final_cost, 1e-12 * summary.final_cost);
  EXPECT_LT((v.vector() - params).cwiseAbs().maxCoeff(), 2e-6);
}

TEST(Solver, StatisticsAreConsistent) {
  auto p = problems::chain(100);
  const auto r = LevenbergMarquardt().optimize(p.graph, p.start);
  ASSERT_TRUE(r.converged());
  EXPECT_EQ(static_cast<int>(r.history.size()), r.trials);
  EXPECT_GE(r.trials, r.iterations);
  double last_accepted = r.initial_error;
  for (const auto& s : r.history) {
    EXPECT_GT(s.lambda, 0.0);
    if (s.accepted) {
      EXPECT_LT(s.error, last_accepted);  // accepted steps decrease the error monotonically
      last_accepted = s.error;
    }
  }
  EXPECT_DOUBLE_EQ(last_accepted, r.final_error);
  EXPECT_NEAR(r.final_error, p.graph.error(p.start), 1e-12 * r.final_error);
  EXPECT_GT(r.factorize_s, 0.0);
  EXPECT_GE(r.total_s, r.linearize_s + r.factorize_s + r.solve_s);
}

TEST(Solver, LinearizingTrialStepsChangesNothingButTheWork) {
  // A trial step evaluated with its Jacobians (kept for the next iteration when accepted) gives
  // the same iterates as evaluating the error alone and linearizing after acceptance. The
  // curve fit from (0, 0) rejects steps, so both branches run.
  for (const problems::Problem& p : {problems::chain(40), problems::curve_fit()}) {
    LevenbergMarquardtOptions reuse_options, fresh_options;
    fresh_options.linearize_at_evaluation = false;
    Values a = p.start, b = p.start;
    const OptimizationResult ra = LevenbergMarquardt(reuse_options).optimize(p.graph, a);
    const OptimizationResult rb = LevenbergMarquardt(fresh_options).optimize(p.graph, b);
    EXPECT_EQ(ra.status, rb.status);
    EXPECT_EQ(ra.iterations, rb.iterations);
    EXPECT_EQ(ra.trials, rb.trials);
    EXPECT_EQ(ra.final_error, rb.final_error);
    EXPECT_EQ(a.vector(), b.vector());
  }
  Values v = problems::curve_fit().start;
  const OptimizationResult r = LevenbergMarquardt().optimize(problems::curve_fit().graph, v);
  EXPECT_GT(r.trials, r.iterations);  // some steps were rejected
}

TEST(Solver, CompactNonzeroRowsKeepsTheInformation) {
  // Zero rows (inactive hinges) are dropped, the others keep their order and residuals, and
  // JᵀJ and Jᵀr are unchanged.
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(6, 4);
  Eigen::VectorXd r(6);
  r << 1, 0, 2, 5, 0, 3;  // row 3 has a residual but no Jacobian: no information either
  J.row(0) << 1, 2, 3, 4;
  J.row(2) << 0, 0, -1, 0;
  J.row(5) << 0.5, 0, 0, 7;
  const Eigen::MatrixXd JtJ = J.transpose() * J;
  const Eigen::VectorXd Jtr = J.transpose() * r;
  Eigen::MatrixXd Jc = J;
  Eigen::VectorXd rc = r;
  const int kept = compact_nonzero_rows(Jc, rc);
  ASSERT_EQ(kept, 3);
  EXPECT_EQ(Jc.row(0), J.row(0));
  EXPECT_EQ(Jc.row(1), J.row(2));
  EXPECT_EQ(Jc.row(2), J.row(5));
  EXPECT_EQ(rc.head(3), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(Jc.topRows(kept).transpose() * Jc.topRows(kept), JtJ);
  EXPECT_EQ(Jc.topRows(kept).transpose() * rc.head(kept), Jtr);
  Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(3, 2);
  Eigen::VectorXd rz = Eigen::VectorXd::Ones(3);
  EXPECT_EQ(compact_nonzero_rows(zero, rz), 0);
}

TEST(Solver, JacobianGramIsJtJOnBothPaths) {
  // Below 16 columns the plain product, from 16 on the symmetric rank update (GP prior and
  // collocation shapes); the full matrix is symmetric, the upper-only one agrees above the
  // diagonal.
  std::mt19937 rng(5);
  std::normal_distribution<double> n01;
  for (const auto& [rows, cols] : {std::pair{7, 21}, std::pair{21, 42}, std::pair{2, 7},
                                   std::pair{14, 42}, std::pair{3, 16}}) {
    Eigen::MatrixXd J(rows, cols);
    for (int i = 0; i < J.size(); ++i) J.data()[i] = n01(rng);
    const Eigen::MatrixXd expected = J.transpose() * J;
    Eigen::MatrixXd full = Eigen::MatrixXd::Constant(cols, cols, 99.0);
    jacobian_gram(J, full, /*upper_only=*/false);
    EXPECT_LT((full - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff())
        << rows << "x" << cols;
    EXPECT_EQ(full, full.transpose());
    Eigen::MatrixXd upper = Eigen::MatrixXd::Constant(cols, cols, 99.0);
    jacobian_gram(J, upper, /*upper_only=*/true);
    const Eigen::MatrixXd diff = Eigen::MatrixXd(upper.triangularView<Eigen::Upper>()) -
                                 Eigen::MatrixXd(expected.triangularView<Eigen::Upper>());
    EXPECT_LT(diff.cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
  }
}

TEST(Solver, NormalEquationsKeepLinearFactorsExactly) {
  // Linear factors keep J and JᵀJ between linearizations (Factor::jacobian_version): H, g and
  // the cost equal a fresh structure's at new values and after a noise-model change.
  const int n = 40;
  auto p = problems::chain(n);
  std::vector<std::shared_ptr<LinearFactor>> linear;
  for (int k = 0; k + 2 < n; k += 3) {
    Eigen::Matrix3d A;
    A << 1, 0.2, 0, -0.1, 1, 0.3, 0, 0.4, 1;
    linear.push_back(p.graph.emplace<LinearFactor>(
        std::vector<Key>{Key('x', 0, k), Key('x', 0, k + 2)},
        std::vector<Eigen::MatrixXd>{A, -A.transpose()}, Eigen::Vector3d(0.1, -0.2, 0.05),
        isotropic(3, 0.5)));
  }
  NormalEquations kept(p.graph, p.start, OrderingMethod::kColamd);
  Values v = p.start;
  double e0 = 0;
  ASSERT_TRUE(kept.linearize(p.graph, v, &e0, nullptr));
  const auto expect_fresh = [&](const char* when) {
    NormalEquations fresh(p.graph, v, OrderingMethod::kColamd);
    double ek = 0, ef = 0;
    ASSERT_TRUE(kept.linearize(p.graph, v, &ek, nullptr));
    ASSERT_TRUE(fresh.linearize(p.graph, v, &ef, nullptr));
    EXPECT_EQ(ek, ef) << when;
    EXPECT_EQ(kept.hessian(), fresh.hessian()) << when;
    EXPECT_EQ(kept.gradient(), fresh.gradient()) << when;
  };
  for (int k = 0; k < n; ++k) {
    const Key key('x', 0, k);
    v.update(key, v.at(key) + Eigen::Vector3d(0.1 * std::sin(k), 0.05, -0.02 * k));
  }
  expect_fresh("at new values");
  linear.front()->set_noise(isotropic(3, 0.1));
  expect_fresh("after a noise change");
}

}  // namespace
}  // namespace kinograph::graph

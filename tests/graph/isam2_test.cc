// ISAM2 against independent references: a dense least-squares solve of the same linear graph,
// batch Levenberg–Marquardt on nonlinear graphs, and the Bayes tree's structural invariants.
#include "kinograph/graph/isam2.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <utility>

#include "kinograph/graph/levenberg_marquardt.h"
#include "kinograph/graph/linear_factor.h"
#include "kinograph/graph/prior_factor.h"

namespace kinograph::graph {
namespace {

Key X(uint32_t i) { return Key('x', 0, i); }

// The whitened Jacobian A and right-hand side b = −r of every factor of the graph stacked
// (dense, columns in the layout's order), linearized at `at` (linear factors at 0 without it).
std::pair<Eigen::MatrixXd, Eigen::VectorXd> stacked_system(const FactorGraph& graph,
                                                           const Values& layout,
                                                           const Values* at) {
  std::vector<std::pair<Eigen::MatrixXd, Eigen::VectorXd>> rows;
  int m = 0;
  Values zero = layout;
  zero.vector().setZero();
  for (const auto& f : graph.factors()) {
    if (!f) continue;
    Eigen::VectorXd r;
    Eigen::MatrixXd J;
    f->linearize(at ? *at : zero, r, J);  // linear factors at 0: r = W(−b), J = W A
    Eigen::MatrixXd Jfull = Eigen::MatrixXd::Zero(J.rows(), layout.total_dim());
    for (size_t k = 0; k < f->keys().size(); ++k) {
      const int s = layout.slot(f->keys()[k]);
      Jfull.middleCols(layout.offset(s), layout.dim(s)) =
          J.middleCols(f->block_offsets()[k], f->dims()[k]);
    }
    rows.emplace_back(Jfull, -r);
    m += static_cast<int>(J.rows());
  }
  Eigen::MatrixXd A(m, layout.total_dim());
  Eigen::VectorXd b(m);
  int r0 = 0;
  for (const auto& [J, rhs] : rows) {
    A.middleRows(r0, J.rows()) = J;
    b.segment(r0, J.rows()) = rhs;
    r0 += static_cast<int>(J.rows());
  }
  return {A, b};
}

// Minimizer of Σ‖W_f (A_f x − b_f)‖² over all (linear) factors of the graph, by dense QR of the
// stacked whitened system: independent of the Bayes tree and of CHOLMOD.
// With `at` given: the Gauss–Newton step of the graph linearized there (dense QR).
Eigen::VectorXd dense_solve(const FactorGraph& graph, const Values& layout,
                            const Values* at = nullptr) {
  const auto [A, b] = stacked_system(graph, layout, at);
  return A.colPivHouseholderQr().solve(b);
}

// The Marquardt step −(H + λD)⁻¹Jᵀr of the graph linearized at `at`, H = JᵀJ, D = diag(H)
// floored at `min_diagonal` (λ = 0: the Gauss–Newton step), by a dense LDLᵀ.
Eigen::VectorXd dense_damped_step(const FactorGraph& graph, const Values& at, double lambda,
                                  double min_diagonal) {
  const auto [A, b] = stacked_system(graph, at, &at);
  const Eigen::MatrixXd H = A.transpose() * A;
  Eigen::MatrixXd damped = H;
  damped.diagonal() += lambda * H.diagonal().cwiseMax(min_diagonal);
  return damped.ldlt().solve(A.transpose() * b);
}

// A random linear factor on the given variables.
FactorPtr random_linear(const std::vector<Key>& keys, const Values& values, std::mt19937& rng) {
  std::normal_distribution<double> n01;
  std::uniform_int_distribution<int> rows_dist(1, 3);
  const int rows = rows_dist(rng);
  std::vector<Eigen::MatrixXd> A;
  for (Key k : keys) {
    Eigen::MatrixXd a(rows, values.dim(values.slot(k)));
    for (int i = 0; i < a.size(); ++i) a.data()[i] = n01(rng);
    A.push_back(a);
  }
  Eigen::VectorXd b(rows);
  for (int i = 0; i < rows; ++i) b[i] = n01(rng);
  return std::make_shared<LinearFactor>(keys, A, b, isotropic(rows, 0.5));
}

TEST(ISAM2, RandomAddsAndRemovesMatchDenseSolveAfterEveryUpdate) {
  std::mt19937 rng(42);
  std::normal_distribution<double> n01;
  ISAM2Options opt;
  opt.wildfire_threshold = 0;
  ISAM2 isam(opt);

  Values all;  // every variable ever added, for the reference solve
  std::vector<size_t> removable;
  int num_vars = 0;
  auto new_variable = [&](Values& nv, std::vector<FactorPtr>& nf) {
    const int dim = 1 + num_vars % 3;
    Eigen::VectorXd x0(dim);
    for (int i = 0; i < dim; ++i) x0[i] = n01(rng);
    const Key k = X(num_vars++);
    nv.insert(k, x0);
    all.insert(k, x0);
    // A weak anchor keeps every variable determined whatever gets removed.
    Eigen::VectorXd t(dim);
    for (int i = 0; i < dim; ++i) t[i] = n01(rng);
    nf.push_back(std::make_shared<PriorFactor>(k, t, isotropic(dim, 3.0)));
    return k;
  };

  {  // Initial chain of 25 variables.
    Values nv;
    std::vector<FactorPtr> nf;
    for (int i = 0; i < 25; ++i) {
      const Key k = new_variable(nv, nf);
      if (i > 0) nf.push_back(random_linear({X(i - 1), k}, all, rng));
    }
    const auto res = isam.update(nf, {}, nv);
    ASSERT_TRUE(res.ok()) << res.reason;
    for (size_t i = 0; i < res.new_factor_indices.size(); ++i) {
      if (i % 2 == 0 && i > 0) removable.push_back(res.new_factor_indices[i]);
    }
  }
  int partial = 0;
  for (int step = 0; step < 120; ++step) {
    Values nv;
    std::vector<FactorPtr> nf;
    std::vector<size_t> removed;
    std::uniform_int_distribution<int> coin(0, 3);
    const bool grows = coin(rng) == 0;
    if (grows) new_variable(nv, nf);
    const int adds = 1 + coin(rng) % 3;
    for (int a = 0; a < adds; ++a) {
      std::uniform_int_distribution<int> pick(0, num_vars - 1);
      std::set<int> chosen;
      const int arity = 1 + coin(rng) % 3;
      // Mostly local factors (as in a trajectory), sometimes a long-range one.
      const int base = pick(rng);
      for (int j = 0; j < arity; ++j) {
        const int v = coin(rng) == 0 ? pick(rng) : std::min(num_vars - 1, base + j);
        chosen.insert(v);
      }
      std::vector<Key> keys;
      for (int v : chosen) keys.push_back(X(v));
      nf.push_back(random_linear(keys, all, rng));
    }
    const int removes = std::min<int>(coin(rng) % 3, static_cast<int>(removable.size()));
    for (int r = 0; r < removes; ++r) {
      std::uniform_int_distribution<size_t> pick(0, removable.size() - 1);
      const size_t i = pick(rng);
      removed.push_back(removable[i]);
      removable.erase(removable.begin() + static_cast<long>(i));
    }
    const auto res = isam.update(nf, removed, nv);
    ASSERT_TRUE(res.ok()) << "step " << step << ": " << res.reason;
    if (!res.full_reelimination) ++partial;
    // Anchors of new variables stay; every other factor may be removed later.
    removable.insert(removable.end(), res.new_factor_indices.begin() + (grows ? 1 : 0),
                     res.new_factor_indices.end());

    ASSERT_EQ(isam.check_invariants(), "") << "step " << step;
    const Eigen::VectorXd expected = dense_solve(isam.graph(), isam.estimate());
    const double err = (isam.estimate().vector() - expected).cwiseAbs().maxCoeff();
    ASSERT_LT(err, 1e-9) << "step " << step;
  }
  EXPECT_GT(partial, 60);  // most updates really were incremental
}

// Chain x_0 … x_{n−1} (dim 2): start prior, neighbour differences, goal prior at the end.
struct Chain {
  std::vector<FactorPtr> factors;
  Values values;
  size_t goal_index = 0;  // position of the goal factor in `factors`
};

Chain make_chain(int n, const Eigen::Vector2d& goal) {
  Chain c;
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  for (int i = 0; i < n; ++i) c.values.insert(X(i), Eigen::Vector2d(n01(rng), n01(rng)));
  c.factors.push_back(
      std::make_shared<PriorFactor>(X(0), Eigen::Vector2d(0, 0), isotropic(2, 0.1)));
  for (int i = 1; i < n; ++i) {
    Eigen::MatrixXd A0 = -Eigen::MatrixXd::Identity(2, 2), A1 = Eigen::MatrixXd::Identity(2, 2);
    A1(0, 1) = 0.3;
    c.factors.push_back(std::make_shared<LinearFactor>(
        std::vector<Key>{X(i - 1), X(i)}, std::vector<Eigen::MatrixXd>{A0, A1},
        Eigen::Vector2d(0.1, -0.05), isotropic(2, 1.0)));
  }
  c.goal_index = c.factors.size();
  c.factors.push_back(std::make_shared<PriorFactor>(X(n - 1), goal, isotropic(2, 0.1)));
  return c;
}

// Options for a linear graph solved exactly: nothing is relinearized unless forced, and
// back-substitution visits every clique.
ISAM2Options exact_linear_options() {
  ISAM2Options opt;
  opt.wildfire_threshold = 0;
  opt.relinearize_threshold = 1e9;
  return opt;
}

TEST(ISAM2, ChangingTheLastFactorReeliminatesOnlyThePathToTheRoot) {
  const int n = 60;
  Chain chain = make_chain(n, Eigen::Vector2d(3, 1));
  ISAM2 isam(exact_linear_options());
  ISAM2UpdateOptions first;
  first.constrained_last = {X(n - 1)};
  auto res = isam.update(chain.factors, {}, chain.values, first);
  ASSERT_TRUE(res.ok()) << res.reason;
  size_t goal = res.new_factor_indices[chain.goal_index];

  for (int round = 0; round < 4; ++round) {
    const BayesTree& tree = isam.bayes_tree();
    // Cliques on the path from the goal variable's clique to its root, before the update.
    std::set<int> path;
    for (int c = tree.clique_of(isam.estimate().slot(X(n - 1))); c >= 0;
         c = tree.clique(c).parent) {
      path.insert(c);
    }
    std::map<int, Eigen::MatrixXd> others;  // every other clique's conditional
    for (int c = 0; c < tree.clique_capacity(); ++c) {
      if (tree.clique(c).alive && !path.count(c)) others[c] = tree.clique(c).R;
    }
    ASSERT_GT(others.size(), 10u);

    auto new_goal = std::make_shared<PriorFactor>(X(n - 1), Eigen::Vector2d(3 - round, 1 + round),
                                                  isotropic(2, 0.1));
    res = isam.update({new_goal}, {goal});
    ASSERT_TRUE(res.ok()) << res.reason;
    goal = res.new_factor_indices[0];
    EXPECT_FALSE(res.full_reelimination);
    EXPECT_EQ(res.cliques_reeliminated, static_cast<int>(path.size())) << "round " << round;
    EXPECT_LE(path.size(), 2u);  // the goal's variable sits at the root
    for (const auto& [c, R] : others) {
      ASSERT_TRUE(tree.clique(c).alive) << "clique " << c << " off the path was rebuilt";
      EXPECT_EQ(tree.clique(c).R, R) << "clique " << c << " off the path changed";
    }
    ASSERT_EQ(isam.check_invariants(), "");
    const Eigen::VectorXd expected = dense_solve(isam.graph(), isam.estimate());
    EXPECT_LT((isam.estimate().vector() - expected).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(ISAM2, ConstrainedLastKeysAreEliminatedAtTheRoot) {
  // A variable in the middle of a chain is eliminated in the root clique only when asked.
  const int n = 30;
  const Chain chain = make_chain(n, Eigen::Vector2d(3, 1));
  auto in_root = [&](const ISAM2UpdateOptions& uo) {
    ISAM2 isam;
    EXPECT_TRUE(isam.update(chain.factors, {}, chain.values, uo).ok());
    const BayesTree& tree = isam.bayes_tree();
    return tree.clique(tree.clique_of(isam.estimate().slot(X(n / 3)))).parent < 0;
  };
  ISAM2UpdateOptions middle_last;
  middle_last.constrained_last = {X(n / 3)};
  EXPECT_TRUE(in_root(middle_last));
  EXPECT_FALSE(in_root(ISAM2UpdateOptions()));
}

// Range between two 2-D points: e = ‖x_i − x_j‖ − d (nonlinear).
class RangeFactor final : public Factor {
 public:
  RangeFactor(Key a, Key b, double d, NoiseModelPtr noise)
      : Factor({a, b}, {2, 2}, 1, std::move(noise)), d_(d) {}
  void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const Jacobians* J) const override {
    const Eigen::Vector2d diff = x[0] - x[1];
    const double r = diff.norm();
    e[0] = r - d_;
    if (J) {
      J->block(0) = diff.transpose() / r;
      J->block(1) = -diff.transpose() / r;
    }
  }

 private:
  double d_;
};

// Norm constraint ‖x‖² − 1 = 0 on a 2-D point (a stiff penalty when weighted heavily).
class UnitNormFactor final : public Factor {
 public:
  UnitNormFactor(Key a, NoiseModelPtr noise) : Factor({a}, {2}, 1, std::move(noise)) {}
  void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const Jacobians* J) const override {
    e[0] = x[0].squaredNorm() - 1;
    if (J) J->block(0) = 2 * x[0].transpose();
  }
};

// One-sided limit x_0 ≤ limit on a 2-D point: r = max(0, x_0 − limit), with no active row
// (zero residual and Jacobian) while the limit holds.
class UpperLimitFactor final : public Factor {
 public:
  UpperLimitFactor(Key a, double limit, NoiseModelPtr noise)
      : Factor({a}, {2}, 1, std::move(noise)), limit_(limit) {}
  void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const Jacobians* J) const override {
    const double over = x[0][0] - limit_;
    e[0] = std::max(over, 0.0);
    if (J) J->block(0) = Eigen::RowVector2d(over > 0 ? 1.0 : 0.0, 0.0);
  }

 private:
  double limit_;
};

Values batch_optimum(const FactorGraph& graph, Values start) {
  LevenbergMarquardtOptions o;
  o.relative_error_tol = 1e-14;
  o.max_iterations = 500;
  LevenbergMarquardt lm(o);
  lm.optimize(graph, start);
  return start;
}

TEST(ISAM2, NonlinearUpdatesConvergeToTheBatchOptimum) {
  // A 2-D "trajectory" built up incrementally, three points per update, with ranges to the
  // previous two points and a weak prior on each.
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.05);
  ISAM2 isam;  // defaults: relinearize at 0.1, wildfire 1e-7, safeguard on
  FactorGraph reference;
  Values initial;
  for (int i = 0; i < 30; i += 3) {
    Values nv;
    std::vector<FactorPtr> nf;
    for (int j = i; j < i + 3; ++j) {
      // A zigzag: every point and its two predecessors form a proper triangle, so the ranges
      // fix it up to a reflection that the prior settles.
      const Eigen::Vector2d truth(j * 0.5, 0.4 * (j % 2));
      const Eigen::Vector2d guess = truth + Eigen::Vector2d(noise(rng), noise(rng)) * 2;
      nv.insert(X(j), guess);
      initial.insert(X(j), guess);
      nf.push_back(std::make_shared<PriorFactor>(
          X(j), truth + Eigen::Vector2d(noise(rng), noise(rng)), isotropic(2, 0.2)));
      for (int back = 1; back <= 2 && j - back >= 0; ++back) {
        const Eigen::Vector2d other(0.5 * (j - back), 0.4 * ((j - back) % 2));
        nf.push_back(std::make_shared<RangeFactor>(
            X(j), X(j - back), (truth - other).norm() + 0.2 * noise(rng), isotropic(1, 0.05)));
      }
    }
    for (const auto& f : nf) reference.add(f);
    const auto res = isam.update(nf, {}, nv);
    ASSERT_TRUE(res.ok()) << res.reason;
    EXPECT_FALSE(res.error_increased);
    ASSERT_EQ(isam.check_invariants(), "");
  }
  ISAM2UpdateOptions force;
  force.force_relinearize = true;
  for (int it = 0; it < 30; ++it) {
    const auto res = isam.update({}, {}, {}, force);
    ASSERT_TRUE(res.ok()) << res.reason;
    EXPECT_FALSE(res.error_increased);
  }
  const Values optimum = batch_optimum(reference, initial);
  EXPECT_LT((isam.estimate().vector() - optimum.vector()).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_NEAR(isam.error(), reference.error(optimum), 1e-8 * reference.error(optimum));
}

TEST(ISAM2, FactorsWithoutActiveRowsAddNothingUntilTheyTurnActive) {
  // A chain of 2-D points with a limit on each; first pulled below the limits (no limit row
  // active), then the last point's prior is replaced by one beyond its limit, so its limit must
  // act again: a limit still counted as zero would leave the point at the new prior.
  const int n = 6;
  ISAM2 isam;
  FactorGraph reference;
  Values initial;
  std::vector<FactorPtr> first;
  for (int i = 0; i < n; ++i) initial.insert(X(i), Eigen::Vector2d(0.1 * i, 0.2));
  for (int i = 0; i < n; ++i) {
    first.push_back(std::make_shared<UpperLimitFactor>(X(i), 1.0, isotropic(1, 0.1)));
    if (i > 0) {
      first.push_back(std::make_shared<RangeFactor>(X(i), X(i - 1), 0.3, isotropic(1, 0.1)));
    }
  }
  std::vector<FactorPtr> priors;
  for (int i = 0; i < n; ++i) {
    priors.push_back(std::make_shared<PriorFactor>(X(i), Eigen::Vector2d(0.1 * i, 0.2 * (i % 2)),
                                                   isotropic(2, 0.5)));
  }
  std::vector<FactorPtr> added = first;
  added.insert(added.end(), priors.begin(), priors.end());
  const auto res = isam.update(added, {}, initial);
  ASSERT_TRUE(res.ok()) << res.reason;
  EXPECT_EQ(res.factors_zero, n);  // every limit holds
  const size_t last_prior = res.new_factor_indices.back();

  const auto beyond = std::make_shared<PriorFactor>(X(n - 1), Eigen::Vector2d(2.0, 0.0),
                                                    isotropic(2, 0.5));
  ASSERT_TRUE(isam.update({beyond}, {last_prior}).ok());
  ISAM2UpdateOptions force;
  force.force_relinearize = true;
  for (int it = 0; it < 40; ++it) ASSERT_TRUE(isam.update({}, {}, {}, force).ok());

  for (const auto& f : first) reference.add(f);
  for (int i = 0; i + 1 < n; ++i) reference.add(priors[i]);
  reference.add(beyond);
  const Values optimum = batch_optimum(reference, initial);
  // The limit holds the last point near 1; without it the point would settle far beyond.
  EXPECT_GT(optimum.at(X(n - 1))[0], 1.0 + 1e-3);
  EXPECT_LT(optimum.at(X(n - 1))[0], 1.1);
  FactorGraph unlimited;
  for (const auto& f : reference.factors()) {
    if (f && f != first[first.size() - 2]) unlimited.add(f);  // all but the last point's limit
  }
  EXPECT_GT(batch_optimum(unlimited, initial).at(X(n - 1))[0], 1.2);
  // The chain is weakly held across its length: the estimate agrees to 1e-4, the error to 1e-9.
  EXPECT_LT((isam.estimate().vector() - optimum.vector()).cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_NEAR(isam.error(), reference.error(optimum), 1e-9 * reference.error(optimum));
}

TEST(ISAM2, FactorsAddedOrRemovedWithoutActiveRowsReeliminateNothing) {
  // Limits on the middle of the chain that hold change no clique: adding and removing them
  // re-eliminates nothing and leaves every conditional as it was. One stays, and must act once
  // the chain is pulled past it: a limit the tree did not hold would let the point through.
  const int n = 20, mid = n / 2;
  Chain chain = make_chain(n, Eigen::Vector2d(3, 1));
  ISAM2 isam(exact_linear_options());
  auto res = isam.update(chain.factors, {}, chain.values);
  ASSERT_TRUE(res.ok()) << res.reason;
  const size_t goal = res.new_factor_indices[chain.goal_index];
  const double x_mid = isam.estimate().at(X(mid))[0];

  const BayesTree& tree = isam.bayes_tree();
  auto conditionals = [&tree] {
    std::map<int, Eigen::MatrixXd> R;
    for (int c = 0; c < tree.clique_capacity(); ++c) {
      if (tree.clique(c).alive) R[c] = tree.clique(c).R;
    }
    return R;
  };
  const std::map<int, Eigen::MatrixXd> before = conditionals();
  const Values estimate = isam.estimate();
  std::vector<FactorPtr> limits;
  for (int i = mid - 2; i <= mid + 2; ++i) {
    limits.push_back(std::make_shared<UpperLimitFactor>(X(i), x_mid + 10, isotropic(1, 0.01)));
  }
  res = isam.update(limits, {});
  ASSERT_TRUE(res.ok()) << res.reason;
  EXPECT_EQ(res.factors_zero, static_cast<int>(limits.size()));
  EXPECT_EQ(res.variables_reeliminated, 0);
  EXPECT_EQ(res.cliques_reeliminated, 0);
  EXPECT_EQ(conditionals(), before);
  EXPECT_EQ(isam.estimate().vector(), estimate.vector());
  ASSERT_EQ(isam.check_invariants(), "");  // every limit is held by exactly one clique
  std::vector<size_t> limit_index = res.new_factor_indices;

  // All but the middle one go again.
  std::vector<size_t> removed = limit_index;
  removed.erase(removed.begin() + 2);
  res = isam.update({}, removed);
  ASSERT_TRUE(res.ok()) << res.reason;
  EXPECT_EQ(res.cliques_reeliminated, 0);
  EXPECT_EQ(conditionals(), before);
  ASSERT_EQ(isam.check_invariants(), "");

  // A goal that pulls the chain far along x: the middle limit turns active as the updates go.
  const double limit = x_mid + 10;
  auto far = std::make_shared<PriorFactor>(X(n - 1), Eigen::Vector2d(60, 1), isotropic(2, 0.1));
  ASSERT_TRUE(isam.update({far}, {goal}).ok());
  ISAM2UpdateOptions force;
  force.force_relinearize = true;
  for (int it = 0; it < 40; ++it) ASSERT_TRUE(isam.update({}, {}, {}, force).ok());
  ASSERT_EQ(isam.check_invariants(), "");
  FactorGraph reference;
  for (size_t i = 0; i < chain.factors.size(); ++i) {
    if (i != chain.goal_index) reference.add(chain.factors[i]);
  }
  reference.add(far);
  const Values unlimited = batch_optimum(reference, chain.values);
  ASSERT_GT(unlimited.at(X(mid))[0], limit + 1);  // without the limit the point passes it
  reference.add(limits[2]);
  const Values optimum = batch_optimum(reference, chain.values);
  EXPECT_LT(optimum.at(X(mid))[0], limit + 0.5);
  EXPECT_LT((isam.estimate().vector() - optimum.vector()).cwiseAbs().maxCoeff(), 1e-4);
}

TEST(ISAM2, ThresholdRelinearizationReachesTheOptimumWithoutForcing) {
  // Same kind of problem, one batch insert, then plain updates with a small threshold.
  ISAM2Options opt;
  opt.relinearize_threshold = 1e-9;
  opt.wildfire_threshold = 0;
  ISAM2 isam(opt);
  FactorGraph reference;
  Values initial;
  std::vector<FactorPtr> nf;
  for (int j = 0; j < 20; ++j) {
    initial.insert(X(j), Eigen::Vector2d(j * 0.5 + 0.1 * std::cos(j), 0.2 * std::sin(j)));
    nf.push_back(
        std::make_shared<PriorFactor>(X(j), Eigen::Vector2d(j * 0.5, 0), isotropic(2, 2.0)));
    if (j > 0) {
      nf.push_back(std::make_shared<RangeFactor>(X(j), X(j - 1), 0.5 + 0.02 * std::sin(3.0 * j),
                                                 isotropic(1, 0.1)));
    }
  }
  for (const auto& f : nf) reference.add(f);
  ASSERT_TRUE(isam.update(nf, {}, initial).ok());
  for (int it = 0; it < 30; ++it) {
    const auto res = isam.update();
    ASSERT_TRUE(res.ok());
  }
  // One more update that relinearizes everything is exactly one Gauss–Newton step.
  ISAM2UpdateOptions force;
  force.force_relinearize = true;
  const auto res = isam.update({}, {}, {}, force);
  ASSERT_TRUE(res.ok());
  ASSERT_EQ(res.lambda, 0);
  const Values& theta = isam.linearization_point();
  const Eigen::VectorXd step = dense_solve(isam.graph(), theta, &theta);
  EXPECT_LT((isam.estimate().vector() - theta.vector() - step).cwiseAbs().maxCoeff(), 1e-9);
  const Values optimum = batch_optimum(reference, initial);
  EXPECT_LT((isam.estimate().vector() - optimum.vector()).cwiseAbs().maxCoeff(), 1e-7);
}

// A stiff problem: a chain of 2-D points that must lie on the unit circle (penalty weight up to
// 1e4, i.e. σ = 0.01), with smoothness between neighbours and start/goal priors, started near
// the origin (radius 0.1) where a Gauss–Newton step on ‖x‖² − 1 overshoots fifty-fold.
struct Stiff {
  std::vector<FactorPtr> factors;
  Values initial;
};
Stiff make_stiff(int n) {
  Stiff s;
  for (int i = 0; i < n; ++i) {
    const double angle = 0.5 * M_PI * i / (n - 1);
    s.initial.insert(X(i), 0.1 * Eigen::Vector2d(std::cos(angle), std::sin(angle)));
    const double weight = i % 3 == 0 ? 1e4 : 1e2;  // σ⁻²
    s.factors.push_back(
        std::make_shared<UnitNormFactor>(X(i), isotropic(1, 1 / std::sqrt(weight))));
    if (i > 0) {
      s.factors.push_back(std::make_shared<LinearFactor>(
          std::vector<Key>{X(i - 1), X(i)},
          std::vector<Eigen::MatrixXd>{-Eigen::MatrixXd::Identity(2, 2),
                                       Eigen::MatrixXd::Identity(2, 2)},
          Eigen::Vector2d::Zero(), isotropic(2, 0.3)));
    }
  }
  s.factors.push_back(
      std::make_shared<PriorFactor>(X(0), Eigen::Vector2d(1, 0), isotropic(2, 0.05)));
  s.factors.push_back(
      std::make_shared<PriorFactor>(X(n - 1), Eigen::Vector2d(0, 1), isotropic(2, 0.05)));
  return s;
}

// Runs ISAM2 with options `a` and with `b` in lockstep on the stiff problem (which rejects steps:
// damping, several trials) for 40 updates, every third relinearizing every variable and the
// others by a threshold of 1e-3 (some variables stay off their estimate); the two must take the
// same trials to the same estimates, update after update. `before(it)` runs before update it,
// `check(ra, rb)` after.
void expect_same_iterates(
    const Stiff& s, ISAM2Options a, ISAM2Options b, const std::function<void(int)>& before,
    const std::function<void(const ISAM2Result&, const ISAM2Result&)>& check) {
  a.relinearize_threshold = b.relinearize_threshold = 1e-3;
  ISAM2 ia(a), ib(b);
  ISAM2UpdateOptions force;
  force.force_relinearize = true;
  for (int it = 0; it < 40; ++it) {
    before(it);
    const ISAM2UpdateOptions& uo = it % 3 == 2 ? force : ISAM2UpdateOptions{};
    const auto ra = it == 0 ? ia.update(s.factors, {}, s.initial, uo) : ia.update({}, {}, {}, uo);
    const auto rb = it == 0 ? ib.update(s.factors, {}, s.initial, uo) : ib.update({}, {}, {}, uo);
    ASSERT_TRUE(ra.ok() && rb.ok()) << ra.reason << rb.reason;
    ASSERT_EQ(ra.trials, rb.trials) << "update " << it;
    ASSERT_EQ(ia.estimate().vector(), ib.estimate().vector()) << "update " << it;
    check(ra, rb);
  }
}

TEST(ISAM2, LinearizingAtEvaluationChangesNothingButTheWork) {
  // Both paths of the reuse are exercised; the reused linearization is the same computation at
  // the same point, so the estimates agree exactly.
  ISAM2Options fresh;
  fresh.linearize_at_evaluation = false;
  int reused = 0, damped = 0;
  expect_same_iterates(make_stiff(15), ISAM2Options(), fresh, [](int) {},
                       [&](const ISAM2Result& a, const ISAM2Result& b) {
                         EXPECT_EQ(a.factors_linearized, b.factors_linearized);
                         EXPECT_EQ(b.factors_reused, 0);
                         EXPECT_LE(a.factors_reused, a.factors_linearized);
                         reused += a.factors_reused;
                         damped += a.trials > 1 ? 1 : 0;
                       });
  EXPECT_GT(reused, 0);
  EXPECT_GT(damped, 0);  // the rejected-step path ran too
}

TEST(ISAM2, KeepingConstantJacobiansChangesNothingButTheWork) {
  // The stiff problem's smoothness and prior factors are linear: their JᵀJ is kept between
  // linearizations, exactly the product a fresh linearization forms, also across a change of
  // one factor's noise model (a new Jacobian) before update 20.
  const Stiff s = make_stiff(15);
  ISAM2Options fresh;
  fresh.reuse_constant_jacobians = false;
  int kept = 0;
  expect_same_iterates(
      s, ISAM2Options(), fresh,
      [&](int it) {
        if (it != 20) return;
        for (const FactorPtr& f : s.factors) {
          if (dynamic_cast<const LinearFactor*>(f.get()) == nullptr) continue;
          std::const_pointer_cast<Factor>(f)->set_noise(isotropic(2, 0.2));
          break;
        }
      },
      [&](const ISAM2Result& a, const ISAM2Result& b) {
        EXPECT_EQ(b.jacobians_kept, 0);
        kept += a.jacobians_kept;
      });
  EXPECT_GT(kept, 0);
}

TEST(ISAM2, PlainGaussNewtonOnAStiffProblemSaysWhenTheErrorRises) {
  const Stiff s = make_stiff(15);
  ISAM2Options opt;
  opt.safeguard = false;
  opt.step = ISAM2Step::kGaussNewton;
  ISAM2 isam(opt);
  // Without the safeguard the error is not evaluated, so the flag cannot be set; the flag
  // contract is tested with evaluation on but damping impossible (lambda_max below λ₀).
  ISAM2Options flag_only;
  flag_only.lambda_max = 1e-3;
  ISAM2 flagged(flag_only);
  const auto res = flagged.update(s.factors, {}, s.initial);
  ASSERT_TRUE(res.ok()) << res.reason;
  EXPECT_TRUE(res.error_evaluated);
  EXPECT_GT(res.error_after, 100 * res.error_before);  // the overshoot GTSAM shows, too
  EXPECT_TRUE(res.error_increased);
  EXPECT_NEAR(flagged.error(), res.error_after, 1e-9 * res.error_after);
  const auto plain = isam.update(s.factors, {}, s.initial);
  ASSERT_TRUE(plain.ok());
  EXPECT_FALSE(plain.error_evaluated);
}

TEST(ISAM2, SafeguardedGaussNewtonMakesProgressOnAStiffProblem) {
  const Stiff s = make_stiff(15);
  FactorGraph reference;
  for (const auto& f : s.factors) reference.add(f);
  ISAM2 isam;  // safeguard on by default
  auto res = isam.update(s.factors, {}, s.initial);
  ASSERT_TRUE(res.ok()) << res.reason;
  double last = res.error_after;
  EXPECT_FALSE(res.error_increased);
  EXPECT_LE(res.error_after, res.error_before);
  EXPECT_GT(res.lambda, 0);  // the first step needed damping
  for (int it = 0; it < 120; ++it) {
    res = isam.update();
    ASSERT_TRUE(res.ok()) << res.reason;
    EXPECT_FALSE(res.error_increased) << "update " << it;
    EXPECT_LE(res.error_after, last * (1 + 1e-9)) << "update " << it;
    EXPECT_NEAR(isam.error(), res.error_after, 1e-8 * std::max(1.0, res.error_after));
    last = res.error_after;
  }
  ISAM2UpdateOptions force;
  force.force_relinearize = true;
  for (int it = 0; it < 20; ++it) ASSERT_TRUE(isam.update({}, {}, {}, force).ok());
  const Values optimum = batch_optimum(reference, s.initial);
  EXPECT_NEAR(isam.error(), reference.error(optimum), 1e-6 * reference.error(optimum));
  EXPECT_LT((isam.estimate().vector() - optimum.vector()).cwiseAbs().maxCoeff(), 1e-5);
}

// From a trust radius of 100 the stiff problem's first update rejects two dogleg steps (the
// Gauss–Newton step, then one of a quarter of its length) and accepts the third.
ISAM2Options wide_dogleg() {
  ISAM2Options opt;
  opt.trust_radius_initial = 100;
  return opt;
}

TEST(ISAM2, DoglegNeverRisesSilentlyAndConvergesOnAStiffProblem) {
  const Stiff s = make_stiff(15);
  FactorGraph reference;
  for (const auto& f : s.factors) reference.add(f);
  ISAM2Options opt = wide_dogleg();
  opt.step = ISAM2Step::kDogleg;
  ISAM2 isam(opt);
  auto res = isam.update(s.factors, {}, s.initial);
  ASSERT_TRUE(res.ok()) << res.reason;
  // Updates whose first dogleg step was rejected (trials: one elimination, then the steps).
  int retried = res.trials > 2 ? 1 : 0;
  for (int it = 0; it < 300 && res.error_after > 0; ++it) {
    if (!res.error_increased) {
      EXPECT_LE(res.error_after, res.error_before * (1 + 1e-9));
    }
    EXPECT_NEAR(isam.error(), res.error_after, 1e-8 * std::max(1.0, res.error_after));
    EXPECT_EQ(res.lambda, 0);  // no Marquardt damping with Dogleg
    res = isam.update();
    ASSERT_TRUE(res.ok()) << res.reason;
    retried += res.trials > 2 ? 1 : 0;
  }
  EXPECT_GT(retried, 0);  // the trust region really shrank within an update
  // Below the relinearization threshold the estimate is θ + δ; relinearizing closes the gap.
  ISAM2UpdateOptions force;
  force.force_relinearize = true;
  for (int it = 0; it < 20; ++it) {
    res = isam.update({}, {}, {}, force);
    ASSERT_TRUE(res.ok());
    if (!res.error_increased) {
      EXPECT_LE(res.error_after, res.error_before * (1 + 1e-9));
    }
  }
  const Values optimum = batch_optimum(reference, s.initial);
  EXPECT_NEAR(isam.error(), reference.error(optimum), 1e-4 * reference.error(optimum));
}

TEST(ISAM2, FixedVariablesStayConstant) {
  Chain chain = make_chain(10, Eigen::Vector2d(2, 2));
  chain.values.set_fixed(X(4));
  ISAM2Options opt;
  opt.wildfire_threshold = 0;
  ISAM2 isam(opt);
  const Eigen::Vector2d x4 = chain.values.at(X(4));
  ASSERT_TRUE(isam.update(chain.factors, {}, chain.values).ok());
  EXPECT_EQ(Eigen::Vector2d(isam.estimate().at(X(4))), x4);
  EXPECT_EQ(isam.check_invariants(), "");
  // Reference: LM with the same variable fixed.
  FactorGraph reference;
  for (const auto& f : chain.factors) reference.add(f);
  const Values optimum = batch_optimum(reference, chain.values);
  EXPECT_LT((isam.estimate().vector() - optimum.vector()).cwiseAbs().maxCoeff(), 1e-8);
}

// Renaming every variable changes nothing but the names: the next update (a new goal on the
// renamed last variable) re-eliminates only its path, as without the renaming, and reaches the
// dense optimum; a renaming that merges two variables throws before anything changes.
TEST(ISAM2, RenamedVariablesKeepTheTree) {
  const int n = 30;
  Chain chain = make_chain(n, Eigen::Vector2d(3, 1));
  ISAM2 isam(exact_linear_options());
  ISAM2UpdateOptions first;
  first.constrained_last = {X(n - 1)};
  auto res = isam.update(chain.factors, {}, chain.values, first);
  ASSERT_TRUE(res.ok()) << res.reason;
  const size_t goal = res.new_factor_indices[chain.goal_index];
  const Eigen::VectorXd before = isam.estimate().vector();
  const auto later = [](Key k) { return Key('y', k.index(), k.step() + 100); };
  EXPECT_THROW(isam.rename_variables([](Key) { return X(0); }), std::invalid_argument);
  isam.rename_variables(later);
  EXPECT_EQ(isam.estimate().vector(), before);
  EXPECT_FALSE(isam.estimate().contains(X(0)));
  EXPECT_TRUE(isam.estimate().contains(Key('y', 0, 100)));
  for (const auto& f : isam.graph().factors()) {
    for (Key k : f->keys()) EXPECT_EQ(k.kind(), 'y');
  }
  EXPECT_EQ(isam.check_invariants(), "");
  auto new_goal = std::make_shared<PriorFactor>(Key('y', 0, 100 + n - 1), Eigen::Vector2d(2, 2),
                                                isotropic(2, 0.1));
  res = isam.update({new_goal}, {goal});
  ASSERT_TRUE(res.ok()) << res.reason;
  EXPECT_FALSE(res.full_reelimination);
  EXPECT_LE(res.cliques_reeliminated, 2);
  const Eigen::VectorXd expected = dense_solve(isam.graph(), isam.estimate());
  EXPECT_LT((isam.estimate().vector() - expected).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(ISAM2, BadInputThrowsBeforeChangingState) {
  Chain chain = make_chain(5, Eigen::Vector2d(1, 0));
  ISAM2 isam;
  ASSERT_TRUE(isam.update(chain.factors, {}, chain.values).ok());
  const Eigen::VectorXd before = isam.estimate().vector();
  const size_t n_factors = isam.graph().num_factors();
  auto unknown = std::make_shared<PriorFactor>(X(99), Eigen::Vector2d(0, 0));
  EXPECT_THROW(isam.update({unknown}), std::invalid_argument);
  EXPECT_THROW(isam.update({}, {1000}), std::out_of_range);
  EXPECT_THROW(isam.update({}, {1, 1}), std::invalid_argument);
  Values dup;
  dup.insert(X(0), Eigen::Vector2d(0, 0));
  EXPECT_THROW(isam.update({}, {}, dup), std::invalid_argument);
  auto wrong_dim = std::make_shared<PriorFactor>(X(1), Eigen::Vector3d(0, 0, 0));
  EXPECT_THROW(isam.update({wrong_dim}), std::invalid_argument);
  EXPECT_EQ(isam.graph().num_factors(), n_factors);
  EXPECT_EQ(isam.estimate().vector(), before);
  ASSERT_TRUE(isam.update({}, {1}).ok());
  EXPECT_THROW(isam.update({}, {1}), std::invalid_argument);
}

TEST(ISAM2, UnderdeterminedVariableIsReportedAndRecoverable) {
  ISAM2Options opt;
  opt.safeguard = false;
  ISAM2 isam(opt);
  Values v;
  v.insert(X(0), Eigen::Vector2d(1, 1));
  v.insert(X(1), Eigen::Vector2d(1, 1));  // no factor constrains x1 yet
  auto p0 = std::make_shared<PriorFactor>(X(0), Eigen::Vector2d(0, 0));
  auto res = isam.update({p0}, {}, v);
  EXPECT_EQ(res.status, ISAM2Status::kSingular);
  EXPECT_NE(res.reason.find("x(0,1)"), std::string::npos) << res.reason;
  res = isam.update({std::make_shared<PriorFactor>(X(1), Eigen::Vector2d(0.5, 0.5))});
  ASSERT_TRUE(res.ok()) << res.reason;
  EXPECT_TRUE(res.full_reelimination);
  EXPECT_EQ(isam.check_invariants(), "");
}

TEST(ISAM2, RelinearizationIsCheckedOnlyEveryKthUpdate) {
  ISAM2Options opt;
  opt.relinearize_skip = 3;
  opt.relinearize_threshold = 1e-12;
  opt.safeguard = false;  // plain Gauss–Newton: no damped steps that force relinearization
  ISAM2 isam(opt);
  Values initial;
  std::vector<FactorPtr> nf;
  for (int j = 0; j < 6; ++j) {
    initial.insert(X(j), Eigen::Vector2d(j * 0.5 + 0.1, 0.1));
    nf.push_back(
        std::make_shared<PriorFactor>(X(j), Eigen::Vector2d(j * 0.5, 0), isotropic(2, 2.0)));
    if (j > 0) nf.push_back(std::make_shared<RangeFactor>(X(j), X(j - 1), 0.5, isotropic(1, 0.1)));
  }
  ASSERT_TRUE(isam.update(nf, {}, initial).ok());  // update 1 (checks, nothing to relinearize)
  std::vector<int> relinearized;
  for (int u = 2; u <= 7; ++u) relinearized.push_back(isam.update().variables_relinearized);
  // Updates 4 and 7 check (every third); the others leave θ alone.
  EXPECT_EQ(relinearized[0], 0);
  EXPECT_EQ(relinearized[1], 0);
  EXPECT_GT(relinearized[2], 0);
  EXPECT_EQ(relinearized[3], 0);
  EXPECT_EQ(relinearized[4], 0);
}

}  // namespace
}  // namespace kinograph::graph

namespace kinograph::graph {
namespace {

Key Y(uint32_t i) { return Key('y', 0, i); }

// Largest clique (frontal + separator dimension) of the tree.
int largest_clique(const BayesTree& tree) {
  int largest = 0;
  for (int c = 0; c < tree.clique_capacity(); ++c) {
    if (tree.clique(c).alive) {
      largest = std::max(largest, tree.clique(c).frontal_dim + tree.clique(c).separator_dim);
    }
  }
  return largest;
}

// A two-strand chain (x_i, y_i as a trajectory's positions and accelerations) with a unary
// factor on every x_i (an obstacle near every state). Replacing all unary factors touches every
// x: ordering them all last would eliminate the y strand first and fill one clique with every x.
TEST(ISAM2, ChangeTouchingMostVariablesKeepsCliquesSmall) {
  const int n = 40;
  auto run = [&](double fraction, int* largest, double* error) {
    std::mt19937 rng(3);
    std::normal_distribution<double> n01;
    Values values;
    std::vector<FactorPtr> factors;
    for (int i = 0; i < n; ++i) {
      values.insert(X(i), Eigen::Vector2d(n01(rng), n01(rng)));
      values.insert(Y(i), Eigen::Vector2d(n01(rng), n01(rng)));
    }
    factors.push_back(
        std::make_shared<PriorFactor>(X(0), Eigen::Vector2d(0, 0), isotropic(2, 0.1)));
    factors.push_back(
        std::make_shared<PriorFactor>(Y(0), Eigen::Vector2d(0, 0), isotropic(2, 0.1)));
    const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(2, 2);
    for (int i = 1; i < n; ++i) {
      factors.push_back(std::make_shared<LinearFactor>(
          std::vector<Key>{X(i - 1), X(i), Y(i)}, std::vector<Eigen::MatrixXd>{-I, I, -0.1 * I},
          Eigen::Vector2d(0.1, 0), isotropic(2, 1.0)));
      factors.push_back(std::make_shared<LinearFactor>(
          std::vector<Key>{Y(i - 1), Y(i)}, std::vector<Eigen::MatrixXd>{-I, I},
          Eigen::Vector2d(0, 0.05), isotropic(2, 1.0)));
    }
    const size_t first_unary = factors.size();
    for (int i = 0; i < n; ++i) {
      factors.push_back(
          std::make_shared<PriorFactor>(X(i), Eigen::Vector2d(1, 0), isotropic(2, 5)));
    }
    ISAM2Options opt = exact_linear_options();
    opt.constrain_touched_fraction = fraction;
    ISAM2 isam(opt);
    auto res = isam.update(factors, {}, values);
    ASSERT_TRUE(res.ok());
    std::vector<FactorPtr> moved;
    std::vector<size_t> removed;
    for (int i = 0; i < n; ++i) {
      moved.push_back(
          std::make_shared<PriorFactor>(X(i), Eigen::Vector2d(1, 0.5), isotropic(2, 5)));
      removed.push_back(res.new_factor_indices[first_unary + i]);
    }
    res = isam.update(moved, removed);
    ASSERT_TRUE(res.ok());
    ASSERT_EQ(isam.check_invariants(), "");
    *largest = largest_clique(isam.bayes_tree());
    *error = (isam.estimate().vector() - dense_solve(isam.graph(), isam.estimate()))
                 .cwiseAbs()
                 .maxCoeff();
  };
  int largest = 0;
  double error = 0;
  run(ISAM2Options().constrain_touched_fraction, &largest, &error);
  EXPECT_LE(largest, 12);
  EXPECT_LT(error, 1e-9);
  run(1.0, &largest, &error);  // always ordering the touched variables last
  EXPECT_GT(largest, 40);
  EXPECT_LT(error, 1e-9);
}

// Every update below relinearizes every variable, so it is one step of the whole graph from the
// last estimate: the dense Marquardt step with the λ the result reports (Gauss–Newton at λ = 0).
// λ follows the options exactly: λ₀ after a rejected undamped trial, ×lambda_factor per further
// rejection, ÷lambda_decrease after an accepted update, 0 once below lambda_min; D is diag(H)
// floored at min_diagonal (above most of the stiff problem's diagonal).
TEST(ISAM2, ForcedUpdatesAreDenseMarquardtStepsOnTheConfiguredSchedule) {
  const Stiff s = make_stiff(15);
  ISAM2Options opt;
  opt.wildfire_threshold = 0;
  opt.lambda_initial = 0.5;
  opt.lambda_factor = 3;
  opt.lambda_decrease = 2;
  opt.lambda_min = 0.05;
  opt.min_diagonal = 1e3;
  ISAM2 isam(opt);
  ISAM2UpdateOptions force;
  force.force_relinearize = true;
  double carried = 0;  // λ the next update starts from
  int from_initial = 0, grown = 0, dropped = 0, damped = 0;
  for (int it = 0; it < 30; ++it) {
    const Eigen::VectorXd before = it == 0 ? s.initial.vector() : isam.estimate().vector();
    const auto res =
        it == 0 ? isam.update(s.factors, {}, s.initial, force) : isam.update({}, {}, {}, force);
    ASSERT_TRUE(res.ok()) << res.reason;
    ASSERT_FALSE(res.error_increased) << "update " << it;
    ASSERT_TRUE(res.full_reelimination);
    double expected = carried;  // λ of each trial in turn, as the safeguard forms it
    for (int t = 1; t < res.trials; ++t) {
      from_initial += expected == 0 ? 1 : 0;
      grown += expected == 0 ? 0 : 1;
      expected = expected == 0 ? opt.lambda_initial : expected * opt.lambda_factor;
    }
    ASSERT_EQ(res.lambda, expected) << "update " << it;
    const Values& theta = isam.linearization_point();
    ASSERT_EQ(theta.vector(), before) << "update " << it;  // relinearized at the last estimate
    const Eigen::VectorXd step =
        dense_damped_step(isam.graph(), theta, res.lambda, opt.min_diagonal);
    EXPECT_LT((isam.estimate().vector() - theta.vector() - step).cwiseAbs().maxCoeff(),
              1e-9 * std::max(1.0, step.norm()))
        << "update " << it;
    damped += res.lambda > 0 ? 1 : 0;
    carried = res.lambda / opt.lambda_decrease;
    if (carried < opt.lambda_min) {
      dropped += carried > 0 ? 1 : 0;
      carried = 0;
    }
  }
  // Every branch of the schedule ran.
  EXPECT_GT(from_initial, 0);
  EXPECT_GT(grown, 0);
  EXPECT_GT(dropped, 0);
  EXPECT_GT(damped, dropped);  // some damping was carried into the next update
}

TEST(ISAM2, APreparedTreeTakesTheForcedUpdatesStepReeliminatingOnlyItsChange) {
  // Each round moves the goal prior of the stiff chain. A updates forcing every moved variable
  // to relinearize; B relinearizes at its estimate first (relinearize_at_estimate, the goal's
  // variable at the root) and then updates: the same damped step, but only the root re-
  // eliminated unless a trial is rejected, when B widens to the whole tree as A does.
  const int n = 15;
  const Stiff s = make_stiff(n);
  ISAM2Options opt;
  opt.wildfire_threshold = 0;
  ISAM2 a(opt), b(opt);
  ISAM2UpdateOptions force;
  force.force_relinearize = true;
  auto ra = a.update(s.factors, {}, s.initial, force);
  auto rb = b.update(s.factors, {}, s.initial, force);
  ASSERT_TRUE(ra.ok() && rb.ok());
  size_t goal_a = ra.new_factor_indices.back(), goal_b = rb.new_factor_indices.back();
  int partial = 0, widened = 0;
  for (int it = 0; it < 25; ++it) {
    const Values estimate = b.estimate();
    const ISAM2Result prepared = b.relinearize_at_estimate({X(n - 1)});
    ASSERT_TRUE(prepared.ok()) << prepared.reason;
    ASSERT_EQ(b.estimate().vector(), estimate.vector()) << "round " << it;  // no step taken
    ASSERT_EQ(b.linearization_point().vector(), estimate.vector()) << "round " << it;
    ASSERT_EQ(b.check_invariants(), "");

    const double angle = 0.05 * it;
    auto goal = [&] {
      return std::make_shared<PriorFactor>(
          X(n - 1), Eigen::Vector2d(std::sin(angle), std::cos(angle)), isotropic(2, 0.05));
    };
    ra = a.update({goal()}, {goal_a}, {}, force);
    rb = b.update({goal()}, {goal_b}, {});
    ASSERT_TRUE(ra.ok() && rb.ok()) << ra.reason << rb.reason;
    goal_a = ra.new_factor_indices[0];
    goal_b = rb.new_factor_indices[0];
    ASSERT_EQ(ra.trials, rb.trials) << "round " << it;
    ASSERT_EQ(ra.lambda, rb.lambda) << "round " << it;
    EXPECT_LT((a.estimate().vector() - b.estimate().vector()).cwiseAbs().maxCoeff(), 1e-9)
        << "round " << it;
    ASSERT_EQ(b.check_invariants(), "");
    if (rb.trials == 1) {
      EXPECT_LT(rb.variables_reeliminated, ra.variables_reeliminated) << "round " << it;
      partial += rb.full_reelimination ? 0 : 1;
    } else {
      EXPECT_TRUE(rb.full_reelimination) << "round " << it;
      ++widened;
    }
  }
  EXPECT_GT(partial, 0);
  EXPECT_GT(widened, 0);  // the rejected-trial path ran too
}

TEST(ISAM2, BandedFullUpdatesTakeTheTreesSteps) {
  // The stiff chain (damped trials included) in lockstep with and without banded full updates:
  // the forced updates relinearize every variable, so B solves them as one banded system and
  // keeps no tree, with the steps of A's tree to rounding.
  const int n = 15;
  const Stiff s = make_stiff(n);
  ISAM2Options opt;
  opt.wildfire_threshold = 0;
  ISAM2Options tree_only = opt;
  tree_only.banded_full_updates = false;
  ISAM2 a(tree_only), b(opt);
  ISAM2UpdateOptions force;
  force.force_relinearize = true;
  ASSERT_TRUE(a.update(s.factors, {}, s.initial, force).ok());
  ASSERT_TRUE(b.update(s.factors, {}, s.initial, force).ok());
  ASSERT_FALSE(b.bayes_tree().empty());  // nothing was relinearized: the tree is built
  int damped = 0;
  for (int it = 0; it < 20; ++it) {
    const ISAM2Result ra = a.update({}, {}, {}, force);
    const ISAM2Result rb = b.update({}, {}, {}, force);
    ASSERT_TRUE(ra.ok() && rb.ok()) << ra.reason << rb.reason;
    ASSERT_EQ(ra.trials, rb.trials) << "update " << it;
    ASSERT_EQ(ra.lambda, rb.lambda) << "update " << it;
    EXPECT_LT((a.estimate().vector() - b.estimate().vector()).cwiseAbs().maxCoeff(), 1e-9)
        << "update " << it;
    EXPECT_GT(ra.cliques_reeliminated, 0);
    EXPECT_EQ(rb.cliques_reeliminated, 0);
    EXPECT_EQ(rb.variables_reeliminated, n);
    EXPECT_TRUE(b.bayes_tree().empty());
    EXPECT_EQ(b.check_invariants(), "");
    damped += rb.trials > 1 ? 1 : 0;
  }
  EXPECT_GT(damped, 0);  // the rejected-step path ran too
}

TEST(ISAM2, AfterABandedUpdateASmallChangeRebuildsTheTree) {
  // A linear chain: a forced update relinearizes every variable (banded, no tree); a new goal
  // then touches one variable and relinearizes none, so the tree is rebuilt whole, and the
  // next new goal re-eliminates only part of it. Every estimate is the dense solution.
  const int n = 40;
  Chain chain = make_chain(n, Eigen::Vector2d(3, 1));
  ISAM2 isam(exact_linear_options());
  ISAM2UpdateOptions force;
  force.force_relinearize = true;
  force.constrained_last = {X(n - 1)};
  ISAM2Result res = isam.update(chain.factors, {}, chain.values, force);
  ASSERT_TRUE(res.ok()) << res.reason;
  size_t goal = res.new_factor_indices[chain.goal_index];
  res = isam.update({}, {}, {}, force);
  ASSERT_TRUE(res.ok()) << res.reason;
  EXPECT_EQ(res.variables_relinearized, n);
  EXPECT_EQ(res.cliques_reeliminated, 0);
  EXPECT_TRUE(isam.bayes_tree().empty());
  EXPECT_LT((isam.estimate().vector() - dense_solve(isam.graph(), isam.estimate()))
                .cwiseAbs()
                .maxCoeff(),
            1e-9);
  ISAM2UpdateOptions last;
  last.constrained_last = {X(n - 1)};
  for (int round = 0; round < 2; ++round) {
    auto new_goal = std::make_shared<PriorFactor>(X(n - 1), Eigen::Vector2d(2 - round, 1 + round),
                                                  isotropic(2, 0.1));
    res = isam.update({new_goal}, {goal}, {}, last);
    ASSERT_TRUE(res.ok()) << res.reason;
    goal = res.new_factor_indices[0];
    EXPECT_EQ(res.variables_relinearized, 0);
    EXPECT_EQ(res.full_reelimination, round == 0) << "round " << round;
    EXPECT_GT(res.cliques_reeliminated, 0);
    ASSERT_EQ(isam.check_invariants(), "");
    EXPECT_LT((isam.estimate().vector() - dense_solve(isam.graph(), isam.estimate()))
                  .cwiseAbs()
                  .maxCoeff(),
              1e-9)
        << "round " << round;
  }
}

TEST(ISAM2, OnlyABandedGraphTakesTheBandedPath) {
  // A star (every variable tied to the first): in slot order its Hessian's envelope is the
  // whole triangle, so a forced update rebuilds the tree, twice in a row, as without the option.
  const int n = 40;
  std::mt19937 rng(11);
  std::vector<FactorPtr> factors;
  Values values;
  for (int i = 0; i < n; ++i) {
    values.insert(X(i), Eigen::Vector2d::Zero());
    factors.push_back(
        std::make_shared<PriorFactor>(X(i), Eigen::Vector2d(0.1 * i, 1), isotropic(2, 1)));
    if (i > 0) factors.push_back(random_linear({X(0), X(i)}, values, rng));
  }
  ISAM2 isam(exact_linear_options());
  ISAM2UpdateOptions force;
  force.force_relinearize = true;
  ASSERT_TRUE(isam.update(factors, {}, values, force).ok());
  for (int it = 0; it < 2; ++it) {
    const ISAM2Result res = isam.update({}, {}, {}, force);
    ASSERT_TRUE(res.ok()) << res.reason;
    EXPECT_EQ(res.variables_relinearized, n);
    EXPECT_GT(res.cliques_reeliminated, 0);
    ASSERT_EQ(isam.check_invariants(), "");
    EXPECT_LT((isam.estimate().vector() - dense_solve(isam.graph(), isam.estimate()))
                  .cwiseAbs()
                  .maxCoeff(),
              1e-9);
  }
}

TEST(ISAM2, AnUnchangedUpdateTakesThePreparedStep) {
  // Relinearizing at the estimate skips the step the new tree holds; the next update takes it
  // even when nothing changed: the forced update's step, so a prepared ISAM2 converges as one.
  const Stiff s = make_stiff(15);
  ISAM2Options opt;
  opt.wildfire_threshold = 0;
  ISAM2 a(opt), b(opt);
  ISAM2UpdateOptions force;
  force.force_relinearize = true;
  ASSERT_TRUE(a.update(s.factors, {}, s.initial, force).ok());
  ASSERT_TRUE(b.update(s.factors, {}, s.initial, force).ok());
  for (int it = 0; it < 60; ++it) {
    const ISAM2Result ra = a.update({}, {}, {}, force);
    ASSERT_TRUE(b.relinearize_at_estimate().ok());
    const ISAM2Result rb = b.update();
    ASSERT_TRUE(ra.ok() && rb.ok()) << ra.reason << rb.reason;
    ASSERT_EQ(ra.trials, rb.trials) << "update " << it;
    EXPECT_LT((a.estimate().vector() - b.estimate().vector()).cwiseAbs().maxCoeff(), 1e-9)
        << "update " << it;
  }
  FactorGraph graph;
  for (const FactorPtr& f : s.factors) graph.add(f);
  const Values optimum = batch_optimum(graph, s.initial);
  EXPECT_LT((b.estimate().vector() - optimum.vector()).cwiseAbs().maxCoeff(), 1e-6);
}

TEST(ISAM2, ErrorRiseToleranceLetsARiseWithinItPass) {
  // The stiff problem's first Gauss–Newton step raises the error a hundredfold and more: by
  // default the safeguard damps it; with a tolerance above that rise it is accepted undamped.
  const Stiff s = make_stiff(15);
  ISAM2Options lax;
  lax.error_rise_tolerance = 1e6;
  ISAM2 strict_isam, lax_isam(lax);
  const auto strict = strict_isam.update(s.factors, {}, s.initial);
  const auto loose = lax_isam.update(s.factors, {}, s.initial);
  ASSERT_TRUE(strict.ok() && loose.ok());
  EXPECT_GT(strict.trials, 1);
  EXPECT_LE(strict.error_after, strict.error_before);
  EXPECT_EQ(loose.trials, 1);
  EXPECT_EQ(loose.lambda, 0);
  EXPECT_GT(loose.error_after, 100 * loose.error_before);
  EXPECT_FALSE(loose.error_increased);  // within the tolerance a rise does not count
}

TEST(ISAM2, WildfireThresholdBoundsTheBackSubstitution) {
  // A goal change on a chain with priors dies out along it (to exactly zero change within
  // about 40 steps): the higher the threshold, the fewer cliques back-substitution visits and
  // the larger the error it leaves.
  const int n = 80;
  int total = 0;  // cliques of the tree
  auto run = [&](double wildfire, int* solved, double* error) {
    Chain chain = make_chain(n, Eigen::Vector2d(1, 1));
    for (int i = 1; i < n; ++i) {
      chain.factors.push_back(
          std::make_shared<PriorFactor>(X(i), Eigen::Vector2d(0.1 * i, 0), isotropic(2, 1.0)));
    }
    ISAM2Options opt;
    opt.wildfire_threshold = wildfire;
    opt.relinearize_threshold = 1e9;
    ISAM2 isam(opt);
    ISAM2UpdateOptions first;
    first.constrained_last = {X(n - 1)};
    auto res = isam.update(chain.factors, {}, chain.values, first);
    ASSERT_TRUE(res.ok());
    res = isam.update(
        {std::make_shared<PriorFactor>(X(n - 1), Eigen::Vector2d(2, 0), isotropic(2, 0.1))},
        {res.new_factor_indices[chain.goal_index]});
    ASSERT_TRUE(res.ok());
    *solved = res.cliques_solved;
    total = isam.bayes_tree().num_cliques();
    *error = (isam.estimate().vector() - dense_solve(isam.graph(), isam.estimate()))
                 .cwiseAbs()
                 .maxCoeff();
  };
  int exact = 0, by_default = 0, coarse = 0;
  double exact_error = 0, default_error = 0, coarse_error = 0;
  run(0, &exact, &exact_error);
  EXPECT_LT(exact_error, 1e-12);
  run(ISAM2Options().wildfire_threshold, &by_default, &default_error);
  EXPECT_LT(by_default, exact);
  EXPECT_LT(by_default, total / 2);
  EXPECT_LT(default_error, 1e-6);
  EXPECT_GT(default_error, exact_error);
  run(1e-2, &coarse, &coarse_error);
  EXPECT_LT(coarse, by_default);
  EXPECT_LT(coarse_error, 1e-1);
  EXPECT_GT(coarse_error, default_error);
}

TEST(ISAM2, FullReeliminationFractionDecidesWhenTheTreeIsRebuilt) {
  // With the goal's end eliminated last, the start prior sits at the bottom: changing it affects
  // the whole path to the root (by default: re-eliminated from scratch), while a goal change
  // affects only the root (by default: in place).
  const int n = 40;
  auto run = [&](double fraction, bool change_start) {
    Chain chain = make_chain(n, Eigen::Vector2d(3, 1));
    ISAM2Options opt = exact_linear_options();
    opt.full_reelimination_fraction = fraction;
    ISAM2 isam(opt);
    ISAM2UpdateOptions first;
    first.constrained_last = {X(n - 1)};
    auto res = isam.update(chain.factors, {}, chain.values, first);
    EXPECT_TRUE(res.ok());
    const int var = change_start ? 0 : n - 1;
    const size_t old = res.new_factor_indices[change_start ? 0 : chain.goal_index];
    res = isam.update(
        {std::make_shared<PriorFactor>(X(var), Eigen::Vector2d(1, -1), isotropic(2, 0.1))}, {old});
    EXPECT_TRUE(res.ok());
    EXPECT_EQ(isam.check_invariants(), "");
    const Eigen::VectorXd expected = dense_solve(isam.graph(), isam.estimate());
    EXPECT_LT((isam.estimate().vector() - expected).cwiseAbs().maxCoeff(), 1e-9);
    return res;
  };
  const double by_default = ISAM2Options().full_reelimination_fraction;
  ISAM2Result res = run(by_default, /*change_start=*/true);
  EXPECT_TRUE(res.full_reelimination);
  EXPECT_EQ(res.variables_reeliminated, n);
  res = run(1.0, /*change_start=*/true);  // never rebuild: the affected top is the whole tree
  EXPECT_FALSE(res.full_reelimination);
  EXPECT_EQ(res.variables_reeliminated, n);
  EXPECT_FALSE(run(by_default, /*change_start=*/false).full_reelimination);
  EXPECT_TRUE(run(0.0, /*change_start=*/false).full_reelimination);  // always rebuild
}

// Runs Dogleg with `opt` on the stiff problem for `updates` updates, `check(it, result, step)`
// after each with the step it took (change of the estimate, ‖·‖₂).
void run_dogleg(ISAM2Options opt, int updates,
                const std::function<void(int, const ISAM2Result&, double)>& check) {
  const Stiff s = make_stiff(15);
  opt.step = ISAM2Step::kDogleg;
  ISAM2 isam(opt);
  for (int it = 0; it < updates; ++it) {
    const Eigen::VectorXd before = it == 0 ? s.initial.vector() : isam.estimate().vector();
    const auto res = it == 0 ? isam.update(s.factors, {}, s.initial) : isam.update();
    ASSERT_TRUE(res.ok()) << res.reason;
    check(it, res, (isam.estimate().vector() - before).norm());
  }
}

TEST(ISAM2, DoglegFirstStepStaysInsideTheInitialTrustRadius) {
  ISAM2Options opt;
  opt.trust_radius_initial = 1e-2;
  run_dogleg(opt, 1, [&](int, const ISAM2Result& res, double step) {
    EXPECT_EQ(res.lambda, 0);  // no Marquardt damping with Dogleg
    EXPECT_GT(step, 0);
    EXPECT_LE(step, opt.trust_radius_initial * (1 + 1e-12));
  });
  // The default radius lets the same first step go much further.
  run_dogleg(ISAM2Options(), 1, [&](int, const ISAM2Result&, double step) {
    EXPECT_GT(step, 10 * opt.trust_radius_initial);
  });
}

TEST(ISAM2, DoglegGivesUpAtTheTrustRadiusFloor) {
  // A floor between the second and third radius ends the first update after two steps,
  // flagged, with the radius at the floor.
  int default_trials = 0;
  run_dogleg(wide_dogleg(), 1, [&](int, const ISAM2Result& res, double) {
    EXPECT_FALSE(res.error_increased);
    default_trials = res.trials;
  });
  EXPECT_EQ(default_trials, 4);  // one elimination, three dogleg steps
  ISAM2Options opt = wide_dogleg();
  opt.trust_radius_min = 2;
  run_dogleg(opt, 1, [&](int, const ISAM2Result& res, double) {
    EXPECT_EQ(res.trials, 3);
    EXPECT_TRUE(res.error_increased);
    EXPECT_EQ(res.trust_radius, opt.trust_radius_min);
  });
}

TEST(ISAM2, DoglegTriesAtMostMaxTrialsPerUpdate) {
  ISAM2Options opt = wide_dogleg();
  opt.max_dogleg_trials = 2;
  run_dogleg(opt, 10, [&](int it, const ISAM2Result& res, double) {
    EXPECT_LE(res.trials, 1 + opt.max_dogleg_trials) << "update " << it;
    if (it == 0) {
      EXPECT_TRUE(res.error_increased);  // its third step was not tried
    }
  });
}

}  // namespace
}  // namespace kinograph::graph

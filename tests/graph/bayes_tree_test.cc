// The Bayes tree alone: multifrontal elimination of hand-made linearized factors against a
// dense solve of H δ = −g, for several orderings, and detach/rebuild of the top.
#include "kinograph/graph/bayes_tree.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <numeric>
#include <random>

namespace kinograph::graph {
namespace {

struct Problem {
  std::vector<int> dims, offsets;
  std::vector<LinearizedFactor> factors;
  int total = 0;
};

// Random factors: a prior on every variable, links between neighbours and a few long-range ones.
Problem random_problem(int n, std::mt19937& rng) {
  Problem p;
  std::normal_distribution<double> n01;
  for (int i = 0; i < n; ++i) {
    p.dims.push_back(1 + i % 3);
    p.offsets.push_back(p.total);
    p.total += p.dims.back();
  }
  auto add = [&](std::vector<int> vars) {
    LinearizedFactor f;
    f.vars = vars;
    int cols = 0;
    for (int v : vars) {
      f.offsets.push_back(cols);
      cols += p.dims[v];
    }
    Eigen::MatrixXd J(cols + 1, cols);
    Eigen::VectorXd r(cols + 1);
    for (int i = 0; i < J.size(); ++i) J.data()[i] = n01(rng);
    for (int i = 0; i < r.size(); ++i) r[i] = n01(rng);
    f.H = J.transpose() * J;
    f.g = J.transpose() * r;
    f.active = true;
    p.factors.push_back(f);
  };
  for (int i = 0; i < n; ++i) add({i});
  for (int i = 1; i < n; ++i) add({i - 1, i});
  std::uniform_int_distribution<int> pick(0, n - 1);
  for (int k = 0; k < n / 4; ++k) {
    const int a = pick(rng), b = pick(rng);
    if (a != b) add({a, b});
  }
  return p;
}

Eigen::VectorXd dense_solution(const Problem& p) {
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(p.total, p.total);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(p.total);
  for (const auto& f : p.factors) {
    for (size_t a = 0; a < f.vars.size(); ++a) {
      g.segment(p.offsets[f.vars[a]], p.dims[f.vars[a]]) +=
          f.g.segment(f.offsets[a], p.dims[f.vars[a]]);
      for (size_t b = 0; b < f.vars.size(); ++b) {
        H.block(p.offsets[f.vars[a]], p.offsets[f.vars[b]], p.dims[f.vars[a]], p.dims[f.vars[b]]) +=
            f.H.block(f.offsets[a], f.offsets[b], p.dims[f.vars[a]], p.dims[f.vars[b]]);
      }
    }
  }
  return H.ldlt().solve(-g);
}

std::vector<int> iota(int n) {
  std::vector<int> v(n);
  std::iota(v.begin(), v.end(), 0);
  return v;
}

TEST(BayesTree, EliminationMatchesDenseSolveForAnyOrdering) {
  std::mt19937 rng(11);
  const Problem p = random_problem(40, rng);
  const Eigen::VectorXd expected = dense_solution(p);
  const std::vector<int> vars = iota(40);
  const std::vector<int> all_factors = iota(static_cast<int>(p.factors.size()));
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<int> order = iota(40);
    if (trial > 0) std::shuffle(order.begin(), order.end(), rng);
    BayesTree tree;
    tree.set_layout(p.dims, p.offsets);
    const auto cliques = tree.build(vars, order, all_factors, p.factors, {});
    ASSERT_TRUE(tree.factorize(cliques, p.factors, nullptr, nullptr));
    EXPECT_EQ(tree.check_invariants(vars, all_factors), "");
    Eigen::VectorXd delta = Eigen::VectorXd::Zero(p.total);
    std::vector<int> changed;
    EXPECT_EQ(tree.back_substitute(0, delta, &changed), static_cast<int>(cliques.size()));
    EXPECT_LT((delta - expected).cwiseAbs().maxCoeff(), 1e-9) << "trial " << trial;
    tree.clear_fresh();
  }
}

TEST(BayesTree, NaturalOrderOfAChainGivesOneCliquePerVariableAndTheRootPair) {
  std::mt19937 rng(5);
  Problem p = random_problem(10, rng);
  p.factors.resize(10 + 9);  // priors and neighbour links only
  BayesTree tree;
  tree.set_layout(p.dims, p.offsets);
  const auto vars = iota(10);
  const auto cliques = tree.build(vars, iota(10), iota(19), p.factors, {});
  EXPECT_EQ(cliques.size(), 9u);  // the last two variables share the root
  const int root = tree.clique_of(9);
  EXPECT_EQ(tree.clique(root).frontals, (std::vector<int>{8, 9}));
  EXPECT_EQ(tree.clique(tree.clique_of(3)).separator, (std::vector<int>{4}));
  EXPECT_EQ(tree.clique(tree.clique_of(3)).parent, tree.clique_of(4));
}

TEST(BayesTree, DetachAndRebuildTheTopGivesTheSameSolution) {
  std::mt19937 rng(23);
  const Problem p = random_problem(30, rng);
  const Eigen::VectorXd expected = dense_solution(p);
  const auto vars = iota(30);
  const auto all_factors = iota(static_cast<int>(p.factors.size()));
  BayesTree tree;
  tree.set_layout(p.dims, p.offsets);
  auto cliques = tree.build(vars, iota(30), all_factors, p.factors, {});
  ASSERT_TRUE(tree.factorize(cliques, p.factors, nullptr, nullptr));
  Eigen::VectorXd delta = Eigen::VectorXd::Zero(p.total);
  tree.back_substitute(0, delta, nullptr);
  tree.clear_fresh();

  for (int marked_var : {3, 17, 29}) {
    // The removed cliques are exactly the marked variable's clique and its ancestors.
    std::vector<int> path_vars;
    for (int c = tree.clique_of(marked_var); c >= 0; c = tree.clique(c).parent) {
      path_vars.insert(path_vars.end(), tree.clique(c).frontals.begin(),
                       tree.clique(c).frontals.end());
    }
    std::vector<int> top, held, orphans;
    tree.detach({marked_var}, &top, &held, &orphans);
    std::sort(top.begin(), top.end());
    std::sort(path_vars.begin(), path_vars.end());
    EXPECT_EQ(top, path_vars);
    for (int o : orphans) EXPECT_LT(tree.clique(o).parent, 0);
    // Rebuild in reverse order of the detached variables.
    std::vector<int> order = iota(static_cast<int>(top.size()));
    std::reverse(order.begin(), order.end());
    cliques = tree.build(top, order, held, p.factors, orphans);
    ASSERT_TRUE(tree.factorize(cliques, p.factors, nullptr, nullptr));
    EXPECT_EQ(tree.check_invariants(vars, all_factors), "") << "marked " << marked_var;
    delta.setZero();  // force a full pass: every clique's value differs from zero
    tree.back_substitute(0, delta, nullptr);
    EXPECT_LT((delta - expected).cwiseAbs().maxCoeff(), 1e-9) << "marked " << marked_var;
    tree.clear_fresh();
  }
}

TEST(BayesTree, NonPositiveDefiniteBlockIsReported) {
  Problem p;
  p.dims = {2, 2};
  p.offsets = {0, 2};
  p.total = 4;
  LinearizedFactor f;
  f.vars = {0, 1};
  f.offsets = {0, 2};
  Eigen::MatrixXd J(1, 4);
  J << 1, 0, -1, 0;  // rank one: neither variable is determined
  f.H = J.transpose() * J;
  f.g = Eigen::VectorXd::Zero(4);
  f.active = true;
  p.factors.push_back(f);
  BayesTree tree;
  tree.set_layout(p.dims, p.offsets);
  const auto cliques = tree.build({0, 1}, {0, 1}, {0}, p.factors, {});
  int bad = -1;
  EXPECT_FALSE(tree.factorize(cliques, p.factors, nullptr, &bad));
  EXPECT_GE(bad, 0);
}

}  // namespace
}  // namespace kinograph::graph

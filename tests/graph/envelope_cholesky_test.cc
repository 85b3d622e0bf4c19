// EnvelopeCholesky against Eigen's dense LLᵀ: banded, block-banded and arrow-shaped patterns, the solve, the
// failure column of a matrix that is not positive definite, and when the envelope wins.
#include "kinograph/graph/envelope_cholesky.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <random>

namespace kinograph::graph {
namespace {

// The upper triangle of a dense symmetric matrix as compressed columns, keeping the entries
// that `keep(i, j)` names (and every diagonal).
struct Pattern {
  int n = 0;
  std::vector<int> col_ptr, row_idx;
  std::vector<double> values;
};
template <class Keep>
Pattern upper_pattern(const Eigen::MatrixXd& A, Keep keep) {
  Pattern p;
  p.n = static_cast<int>(A.rows());
  p.col_ptr.push_back(0);
  for (int j = 0; j < p.n; ++j) {
    for (int i = 0; i <= j; ++i) {
      if (i == j || keep(i, j)) {
        p.row_idx.push_back(i);
        p.values.push_back(A(i, j));
      }
    }
    p.col_ptr.push_back(static_cast<int>(p.row_idx.size()));
  }
  return p;
}

// A random SPD matrix whose (i, j) entries are zero unless `keep(i, j)`.
template <class Keep>
Eigen::MatrixXd random_spd(int n, unsigned seed, Keep keep) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> N;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < j; ++i) {
      if (keep(i, j)) A(i, j) = A(j, i) = N(rng);
    }
  }
  for (int j = 0; j < n; ++j) A(j, j) = A.row(j).cwiseAbs().sum() + 1.0;  // diagonally dominant
  return A;
}

void expect_solves_like_dense(const Eigen::MatrixXd& A, Pattern p) {
  EnvelopeCholesky chol(p.n, p.col_ptr, p.row_idx);
  std::copy(p.values.begin(), p.values.end(), chol.values());
  ASSERT_TRUE(chol.factorize());
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(p.n, -1.0, 2.0);
  Eigen::VectorXd x(p.n);
  chol.solve(b, x);
  const Eigen::VectorXd expected = A.llt().solve(b);
  EXPECT_LT((x - expected).norm(), 1e-12 * expected.norm());
  // A second factorization of new values reuses the storage and is as exact.
  for (double& v : p.values) v *= 2.0;
  std::copy(p.values.begin(), p.values.end(), chol.values());
  ASSERT_TRUE(chol.factorize());
  chol.solve(b, x);
  EXPECT_LT((x - 0.5 * expected).norm(), 1e-12 * expected.norm());
}

TEST(EnvelopeCholesky, BandedMatrixSolvesLikeDenseLlt) {
  const auto band = [](int i, int j) { return j - i <= 9 && (i + j) % 3 != 0; };  // holes inside
  const Eigen::MatrixXd A = random_spd(120, 1, band);
  const Pattern p = upper_pattern(A, band);
  expect_solves_like_dense(A, p);
  EXPECT_TRUE(EnvelopeCholesky::wins(p.n, p.col_ptr, p.row_idx));
}

// States of 7 variables coupled to the state before, as a trajectory graph in time order, with
// holes: most rows of a state share their first column.
bool block_band(int i, int j) { return j / 7 - i / 7 <= 1 && (i * 5 + j) % 11 != 0; }

TEST(EnvelopeCholesky, BlockBandedMatrixSolvesLikeDenseLlt) {
  const Eigen::MatrixXd A = random_spd(7 * 30, 5, block_band);
  expect_solves_like_dense(A, upper_pattern(A, block_band));
}

TEST(EnvelopeCholesky, RaggedEnvelopeSolvesLikeDenseLlt) {
  // Every row starts at its own column and the size is no multiple of the rows stored
  // together: rows of a group padded to the group's first column, and a last partial group.
  for (int n : {1, 2, 5, 37, 38, 39, 40}) {
    std::mt19937 rng(11 + n);
    std::uniform_int_distribution<int> reach(0, 12);
    std::vector<int> first(n);
    for (int j = 0; j < n; ++j) first[j] = std::max(0, j - reach(rng));
    const auto ragged = [&first](int i, int j) { return i >= first[j]; };
    const Eigen::MatrixXd A = random_spd(n, 20 + n, ragged);
    expect_solves_like_dense(A, upper_pattern(A, ragged));
  }
}

TEST(EnvelopeCholesky, NotPositiveDefiniteInsideAStateNamesTheColumn) {
  Eigen::MatrixXd A = random_spd(7 * 10, 6, block_band);
  A(7 * 4 + 3, 7 * 4 + 3) = -1.0;
  const Pattern p = upper_pattern(A, block_band);
  EnvelopeCholesky chol(p.n, p.col_ptr, p.row_idx);
  std::copy(p.values.begin(), p.values.end(), chol.values());
  EXPECT_FALSE(chol.factorize());
  EXPECT_EQ(chol.failed_column(), 7 * 4 + 3);
}

TEST(EnvelopeCholesky, ArrowWithTheHubLastSolvesAndWins) {
  const int n = 60;
  const auto arrow = [n](int i, int j) { return j - i <= 2 || j >= n - 3; };
  const Eigen::MatrixXd A = random_spd(n, 2, arrow);
  const Pattern p = upper_pattern(A, arrow);
  expect_solves_like_dense(A, p);
  EXPECT_TRUE(EnvelopeCholesky::wins(p.n, p.col_ptr, p.row_idx));
}

TEST(EnvelopeCholesky, ArrowWithTheHubFirstFillsAndLoses) {
  const auto arrow = [](int i, int j) { return j - i <= 1 || i < 2; };
  const Eigen::MatrixXd A = random_spd(200, 3, arrow);
  const Pattern p = upper_pattern(A, arrow);
  expect_solves_like_dense(A, p);  // still right, only slow
  EXPECT_FALSE(EnvelopeCholesky::wins(p.n, p.col_ptr, p.row_idx));
}

TEST(EnvelopeCholesky, NotPositiveDefiniteNamesTheColumn) {
  const auto band = [](int i, int j) { return j - i <= 3; };
  Eigen::MatrixXd A = random_spd(40, 4, band);
  A(17, 17) = -1.0;
  const Pattern p = upper_pattern(A, band);
  EnvelopeCholesky chol(p.n, p.col_ptr, p.row_idx);
  std::copy(p.values.begin(), p.values.end(), chol.values());
  EXPECT_FALSE(chol.factorize());
  EXPECT_EQ(chol.failed_column(), 17);
}

TEST(EnvelopeCholesky, AColumnWithoutItsDiagonalIsRefused) {
  // 2×2 with the (1, 1) entry missing from the pattern.
  EXPECT_THROW(EnvelopeCholesky(2, {0, 1, 2}, {0, 0}), std::invalid_argument);
}

}  // namespace
}  // namespace kinograph::graph

// Cooperative cancellation: with this thread's flag set, LM, Gauss–Newton and ISAM2 stop with
// graph::Cancelled before changing the values; without a flag, or with it clear, they solve.
#include "kinograph/graph/cancellation.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "kinograph/graph/gauss_newton.h"
#include "kinograph/graph/isam2.h"
#include "kinograph/graph/levenberg_marquardt.h"
#include "kinograph/graph/prior_factor.h"

namespace kinograph::graph {
namespace {

const Key kX('x', 0, 0);

FactorGraph prior_graph() {
  FactorGraph g;
  g.emplace<PriorFactor>(kX, Eigen::VectorXd::Constant(1, 2.0));
  return g;
}

Values start() {
  Values v;
  v.insert(kX, Eigen::VectorXd::Constant(1, -1.0));
  return v;
}

TEST(Cancellation, ASetFlagStopsEverySolverBeforeItMovesTheValues) {
  const FactorGraph g = prior_graph();
  std::atomic<bool> cancel{true};
  CancellationScope scope(cancel);
  Values v = start();
  EXPECT_THROW(LevenbergMarquardt().optimize(g, v), Cancelled);
  EXPECT_THROW(GaussNewton().optimize(g, v), Cancelled);
  ISAM2 isam;
  EXPECT_THROW(isam.update(g.factors(), {}, v), Cancelled);
  EXPECT_EQ(v.at(kX)(0), -1.0);
}

TEST(Cancellation, AClearFlagOrNoneSolves) {
  const FactorGraph g = prior_graph();
  Values v = start();
  EXPECT_TRUE(LevenbergMarquardt().optimize(g, v).converged());
  EXPECT_NEAR(v.at(kX)(0), 2.0, 1e-9);
  std::atomic<bool> cancel{false};
  CancellationScope scope(cancel);
  v = start();
  EXPECT_TRUE(LevenbergMarquardt().optimize(g, v).converged());
  EXPECT_NEAR(v.at(kX)(0), 2.0, 1e-9);
}

TEST(Cancellation, TheFlagIsThisThreadsAndScopesNest) {
  std::atomic<bool> set{true}, clear{false};
  CancellationScope outer(set);
  {
    CancellationScope inner(clear);
    EXPECT_NO_THROW(throw_if_cancelled());
  }
  EXPECT_THROW(throw_if_cancelled(), Cancelled);
  bool other_thread_threw = false;
  std::thread([&] {
    try {
      throw_if_cancelled();
    } catch (const Cancelled&) {
      other_thread_threw = true;
    }
  }).join();
  EXPECT_FALSE(other_thread_threw);
}

// The planners turn a std::exception from a solve into a failed plan; a cancellation must not
// be one of them.
TEST(Cancellation, IsNotAStdException) {
  std::atomic<bool> set{true};
  CancellationScope scope(set);
  bool caught_as_std = false, caught_as_cancelled = false;
  try {
    try {
      throw_if_cancelled();
    } catch (const std::exception&) {
      caught_as_std = true;
    }
  } catch (const Cancelled&) {
    caught_as_cancelled = true;
  }
  EXPECT_FALSE(caught_as_std);
  EXPECT_TRUE(caught_as_cancelled);
}

}  // namespace
}  // namespace kinograph::graph

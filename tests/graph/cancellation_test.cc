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

// e = x² − 4 on one scalar; every evaluation counts, and the call numbered `trip` sets the flag
// (a shutdown asked for while the solver is inside a linearization).
class Tripwire final : public Factor {
 public:
  Tripwire(Key key, int* calls, int trip, std::atomic<bool>* flag)
      : Factor({key}, {1}, 1), calls_(calls), trip_(trip), flag_(flag) {}
  void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const Jacobians* J) const override {
    if (++*calls_ == trip_) flag_->store(true);
    e(0) = x[0](0) * x[0](0) - 4;
    if (J) J->block(0)(0, 0) = 2 * x[0](0);
  }

 private:
  int* calls_;
  int trip_;
  std::atomic<bool>* flag_;
};

// A long linearization looks at the flag on its way, not only at its end: set in the middle of
// the first trial's evaluation of a 600-factor graph, LM stops there, with the values it had.
TEST(Cancellation, ALinearizationUnderWayStopsAndKeepsTheLastAcceptedPoint) {
  constexpr int kFactors = 600;
  std::atomic<bool> cancel{false};
  int calls = 0;
  FactorGraph g;
  Values v;
  for (int i = 0; i < kFactors; ++i) {
    g.emplace<Tripwire>(Key('x', i, 0), &calls, kFactors + 100, &cancel);
    v.insert(Key('x', i, 0), Eigen::VectorXd::Constant(1, 1.0));
  }
  CancellationScope scope(cancel);
  EXPECT_THROW(LevenbergMarquardt().optimize(g, v), Cancelled);
  EXPECT_LT(calls, 2 * kFactors);  // the trial's pass over the graph did not finish
  for (int i = 0; i < kFactors; ++i) EXPECT_EQ(v.at(Key('x', i, 0))(0), 1.0);
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

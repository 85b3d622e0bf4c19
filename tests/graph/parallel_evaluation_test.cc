// Factors evaluated on several threads (LevenbergMarquardtOptions::threads): the same H, g and
// cost to the bit as on one, the work really shared, factors that are not parallel_safe kept
// on the caller's thread, a factor's exception brought back to the caller, and the choice
// between sharing out and running alone.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "kinograph/graph/cancellation.h"
#include "kinograph/graph/levenberg_marquardt.h"
#include "kinograph/graph/normal_equations.h"
#include "kinograph/graph/share_out_choice.h"
#include "kinograph/graph/worker_local.h"
#include "kinograph/graph/worker_pool.h"

namespace kinograph::graph {
namespace {

// Threads seen by the factors of one test.
struct Seen {
  std::mutex mutex;
  std::condition_variable changed;
  std::set<std::thread::id> threads, caller_only_threads;
  int met = 0;             // rendezvous factors entered
  bool waited_out = false;  // a rendezvous factor's wait ran out: no second thread came
};

// A nonlinear factor on two scalars, e = [sin(a) + b² − t, a·b], that notes its thread. A
// rendezvous factor also waits (up to a minute) until a second one is entered: with two
// threads at work both get there, with one the wait runs out.
class NotingFactor final : public Factor {
 public:
  NotingFactor(Key a, Key b, double t, bool safe, bool rendezvous, Seen& seen,
               bool throws = false)
      : Factor({a, b}, {1, 1}, 2), t_(t), safe_(safe), rendezvous_(rendezvous), throws_(throws),
        seen_(seen) {}
  void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const Jacobians* J) const override {
    note();
    if (throws_) throw std::runtime_error("factor refuses");
    const double a = x[0][0], b = x[1][0];
    e << std::sin(a) + b * b - t_, a * b;
    if (J == nullptr) return;
    J->block(0)(0, 0) = std::cos(a);
    J->block(1)(0, 0) = 2 * b;
    J->block(0)(1, 0) = b;
    J->block(1)(1, 0) = a;
  }
  bool parallel_safe() const override { return safe_; }

 private:
  void note() const {
    std::unique_lock<std::mutex> lock(seen_.mutex);
    seen_.threads.insert(std::this_thread::get_id());
    if (!safe_) seen_.caller_only_threads.insert(std::this_thread::get_id());
    if (!rendezvous_) return;
    ++seen_.met;
    seen_.changed.notify_all();
    if (!seen_.changed.wait_for(lock, std::chrono::minutes(1), [&] { return seen_.met >= 2; })) {
      seen_.waited_out = true;
    }
  }

  double t_;
  bool safe_, rendezvous_, throws_;
  Seen& seen_;
};

struct Chain {
  FactorGraph graph;
  Values values;
};

// A chain of n scalars with a parallel_safe factor between neighbours, every fifth one not
// parallel_safe; the first and the last meet when `rendezvous` (far apart, so that no worker
// takes both in one share of the work).
Chain chain(int n, Seen& seen, bool rendezvous) {
  Chain c;
  for (int k = 0; k < n; ++k) c.values.insert(Key('x', 0, k), Eigen::VectorXd::Constant(1, 0.1 * k));
  for (int k = 0; k + 1 < n; ++k) {
    const bool safe = k % 5 != 4;
    c.graph.emplace<NotingFactor>(Key('x', 0, k), Key('x', 0, k + 1), std::cos(k), safe,
                                  rendezvous && (k == 0 || k == n - 2), seen);
  }
  return c;
}

bool two_cores() { return std::thread::hardware_concurrency() >= 2; }

// Two LM iterations on a chain of 100 with `threads`.
void solve_chain(int threads, Seen& seen, bool rendezvous) {
  Chain c = chain(100, seen, rendezvous);
  LevenbergMarquardtOptions o;
  o.threads = threads;
  o.max_iterations = 2;
  Values v = c.values;
  LevenbergMarquardt(o).optimize(c.graph, v);
}

TEST(ParallelEvaluation, SameNormalEquationsToTheBitOnAnyNumberOfThreads) {
  Seen seen;
  Chain c = chain(200, seen, false);
  NormalEquations one(c.graph, c.values, OrderingMethod::kColamd, 1);
  double e1 = 0;
  ASSERT_TRUE(one.linearize(c.graph, c.values, &e1, nullptr));
  for (int threads : {2, 3, 8}) {
    NormalEquations many(c.graph, c.values, OrderingMethod::kColamd, threads);
    double e = 0, f = 0, f1 = 0;
    ASSERT_TRUE(many.linearize(c.graph, c.values, &e, nullptr));
    EXPECT_EQ(e, e1) << threads;
    EXPECT_EQ(many.hessian(), one.hessian()) << threads;
    EXPECT_EQ(many.gradient(), one.gradient()) << threads;
    ASSERT_TRUE(many.evaluate_error(c.graph, c.values, &f, nullptr));
    ASSERT_TRUE(one.evaluate_error(c.graph, c.values, &f1, nullptr));
    EXPECT_EQ(f, f1) << threads;
  }
  // Whole solves agree too.
  LevenbergMarquardtOptions o;
  o.threads = 1;
  Values v1 = c.values;
  const OptimizationResult r1 = LevenbergMarquardt(o).optimize(c.graph, v1);
  o.threads = 2;
  Values v2 = c.values;
  const OptimizationResult r2 = LevenbergMarquardt(o).optimize(c.graph, v2);
  EXPECT_EQ(r1.iterations, r2.iterations);
  EXPECT_EQ(r1.final_error, r2.final_error);
  EXPECT_EQ(v1.vector(), v2.vector());
}

TEST(ParallelEvaluation, TwoThreadsShareTheWorkAndCallerOnlyFactorsStayOnTheCaller) {
  if (!two_cores()) GTEST_SKIP() << "one core: the pool has no thread";
  Seen seen;
  solve_chain(2, seen, true);
  EXPECT_FALSE(seen.waited_out);       // the rendezvous was met by two threads at once
  EXPECT_EQ(seen.threads.size(), 2u);
  ASSERT_EQ(seen.caller_only_threads.size(), 1u);
  EXPECT_EQ(*seen.caller_only_threads.begin(), std::this_thread::get_id());
}

TEST(ParallelEvaluation, OneThreadKeepsEverythingOnTheCaller) {
  Seen seen;
  solve_chain(1, seen, false);
  ASSERT_EQ(seen.threads.size(), 1u);
  EXPECT_EQ(*seen.threads.begin(), std::this_thread::get_id());
}

TEST(ParallelEvaluation, AFactorsExceptionReachesTheCaller) {
  Seen seen;
  Chain c = chain(100, seen, false);
  c.graph.emplace<NotingFactor>(Key('x', 0, 50), Key('x', 0, 60), 0.0, true, false, seen, true);
  NormalEquations eq(c.graph, c.values, OrderingMethod::kColamd, 2);
  double e = 0;
  EXPECT_THROW(eq.linearize(c.graph, c.values, &e, nullptr), std::runtime_error);
  // The pool is free again: the next linearization of a sound graph runs.
  Chain sound = chain(100, seen, false);
  NormalEquations ok(sound.graph, sound.values, OrderingMethod::kColamd, 2);
  EXPECT_TRUE(ok.linearize(sound.graph, sound.values, &e, nullptr));
}

// A pool thread that helps a caller sees the caller's cancellation flag: its
// throw_if_cancelled() throws, and the caller gets the Cancelled.
TEST(ParallelEvaluation, TheCallersCancellationReachesItsHelpers) {
  if (!two_cores()) GTEST_SKIP() << "one core: the pool has no thread";
  const std::atomic<bool> cancelled{true};
  const CancellationScope scope(cancelled);
  Seen seen;
  bool helper_ran = false;
  auto body = [&](int worker) {
    {  // both workers meet first, so that the helper surely takes part in the job
      std::unique_lock<std::mutex> lock(seen.mutex);
      ++seen.met;
      seen.changed.notify_all();
      seen.waited_out = !seen.changed.wait_for(lock, std::chrono::minutes(1),
                                               [&] { return seen.met >= 2; });
      if (worker == 0) return;
      helper_ran = true;
    }
    throw_if_cancelled();
  };
  EXPECT_THROW(run_on_workers(2, body), Cancelled);
  EXPECT_FALSE(seen.waited_out);
  EXPECT_TRUE(helper_ran);
}

// The choice shares the first two jobs, then runs one alone, then keeps to the faster way and
// tries the other once every kProbeEvery jobs.
TEST(ParallelEvaluation, ShareOutChoiceKeepsToTheFasterWayAndProbesTheOther) {
  for (const bool sharing_faster : {true, false}) {
    ShareOutChoice choice;
    const auto run = [&](bool shared) {
      choice.record(shared, 100, shared == sharing_faster ? 1e-3 : 2e-3);
    };
    ASSERT_TRUE(choice.share());  // first: one-time costs, not timed
    run(true);
    ASSERT_TRUE(choice.share());
    run(true);
    ASSERT_FALSE(choice.share());
    run(false);
    int other = 0;
    for (int job = 0; job < 4 * ShareOutChoice::kProbeEvery; ++job) {
      const bool shared = choice.share();
      other += shared != sharing_faster;
      run(shared);
    }
    EXPECT_EQ(other, 4) << (sharing_faster ? "sharing faster" : "alone faster");
  }
}

TEST(ParallelEvaluation, WorkerLocalGivesEachWorkerItsOwn) {
  int made = 0;
  WorkerLocal<int> local([&made] { return std::make_unique<int>(++made); });
  EXPECT_EQ(made, 1);  // the caller's at once
  EXPECT_EQ(current_worker(), 0);
  EXPECT_EQ(local.local(), 1);
  EXPECT_EQ(&local.local(), &local.local());
  EXPECT_EQ(made, 1);
}

}  // namespace
}  // namespace kinograph::graph

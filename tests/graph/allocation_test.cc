// The solver's iterations allocate nothing: a warm re-solve (structure cached) performs the same
// number of heap allocations whether it runs one iteration or many.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>

#include "bench/graph/planning_problem.h"
#include "kinograph/graph/levenberg_marquardt.h"

// Counting malloc itself (glibc lets a program interpose it) catches operator new, Eigen's
// aligned_malloc and CHOLMOD's allocations alike.
// Only the test's own thread counts: on several threads, a pool thread makes its scratch the
// first time it evaluates a factor of each size, in whichever solve that happens to fall.
namespace {
std::atomic<long> g_allocations{0};
thread_local bool t_counted = false;
void count() {
  if (t_counted) ++g_allocations;
}
}

// AddressSanitizer owns malloc itself, so under it the counting (and the test) is left out.
#if !defined(__SANITIZE_ADDRESS__)
extern "C" void* __libc_malloc(std::size_t);
extern "C" void* __libc_calloc(std::size_t, std::size_t);
extern "C" void* __libc_realloc(void*, std::size_t);

extern "C" void* malloc(std::size_t size) {
  count();
  return __libc_malloc(size);
}
extern "C" void* calloc(std::size_t n, std::size_t size) {
  count();
  return __libc_calloc(n, size);
}
extern "C" void* realloc(void* p, std::size_t size) {
  count();
  return __libc_realloc(p, size);
}

#endif

namespace kinograph::graph {
namespace {

long allocations_of_warm_solve(const problems::Problem& p, int max_iterations, int threads) {
  LevenbergMarquardtOptions o;
  o.max_iterations = max_iterations;
  o.threads = threads;
  // What kAuto picks for planning-sized systems; CHOLMOD's supernodal path allocates internally.
  o.factorization = Factorization::kSimplicial;
  o.relative_error_tol = 0;  // run the full iteration budget
  LevenbergMarquardt lm(o);
  Values v = p.start;
  lm.optimize(p.graph, v);  // builds the structure
  v = p.start;
  const long before = g_allocations.load();
  const auto r = lm.optimize(p.graph, v);
  const long count = g_allocations.load() - before;
  EXPECT_EQ(r.iterations, max_iterations);
  return count;
}

TEST(Allocation, IterationsAllocateNothing) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "malloc is AddressSanitizer's";
#endif
  // Planning-shaped: Gaussian GP prior (21×21), dynamics, hinges, priors.
  const auto p = bench::planning_problem(30, 7);
  t_counted = true;
  for (int threads : {1, 2}) {  // on two, the caller evaluates its share and adds them all up
    const long one = allocations_of_warm_solve(p, 1, threads);
    const long many = allocations_of_warm_solve(p, 12, threads);
    EXPECT_EQ(one, many) << threads << " threads";
    EXPECT_LT(one, 20);  // a few per solve: workspace vectors and the history reserve
  }
  t_counted = false;
}

}  // namespace
}  // namespace kinograph::graph

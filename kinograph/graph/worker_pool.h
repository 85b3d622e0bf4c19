#pragma once
// The process's helper threads for evaluating a graph's factors on several cores. One job runs
// at a time; a caller that finds the pool serving another does its job alone, so callers never
// wait for each other and a job's work is only ever split, never changed.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <vector>

namespace kinograph::graph {

/// Most workers a job can have (the caller and the pool's threads); WorkerLocal keeps a slot
/// for each.
inline constexpr int kMaxWorkers = 8;

/// The worker running on this thread: 0 on any caller's thread, 1… on the pool's threads.
int current_worker();

/// Runs `body(context, w)` on the calling thread (w = 0) and on up to `workers` − 1 of the
/// pool's threads (w = 1…), and returns how many ran when every call has. Fewer run when the
/// machine has fewer cores, the pool is serving another caller, `workers` ≤ 1, or a pool thread
/// has not started by the time the caller's call returns (it then stays out): `body` must share
/// out its work dynamically so that worker 0 alone finishes it. An exception thrown by any call
/// is rethrown here (the caller's first, else the first caught), after all calls have returned.
/// The caller's cancellation flag (cancellation.h) is installed on the pool threads for their
/// calls, so throw_if_cancelled() stops the helpers' share too.
/// Allocates nothing once the pool's threads are started.
using WorkerBody = void (*)(void* context, int worker);
int run_on_workers(int workers, WorkerBody body, void* context);

/// The same for a callable `body(int worker)`.
template <class F>
int run_on_workers(int workers, F& body) {
  return run_on_workers(
      workers, [](void* c, int w) { (*static_cast<F*>(c))(w); }, &body);
}

/// Calls `one(item, worker)` on up to `workers` workers (run_on_workers): every item of
/// `caller_only` on worker 0 first, then every item of `any` on whichever worker takes it,
/// `chunk` items at a time. After a call throws no worker takes further items, and the
/// exception is rethrown. Returns how many workers ran.
template <class F>
int share_out(int workers, const std::vector<int>& caller_only, const std::vector<int>& any,
              F& one, size_t chunk = 4) {
  std::atomic<size_t> next{0};
  std::atomic<bool> stop{false};
  auto body = [&](int worker) {
    try {
      if (worker == 0) {
        for (int item : caller_only) one(item, 0);
      }
      const size_t n = any.size();
      for (size_t i = next.fetch_add(chunk); i < n && !stop; i = next.fetch_add(chunk)) {
        for (size_t j = i; j < std::min(n, i + chunk); ++j) one(any[j], worker);
      }
    } catch (...) {
      stop = true;
      throw;
    }
  };
  return run_on_workers(workers, body);
}

}  // namespace kinograph::graph

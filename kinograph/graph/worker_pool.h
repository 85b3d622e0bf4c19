#pragma once
// The process's helper threads for evaluating a graph's factors on several cores. One job runs
// at a time; a caller that finds the pool serving another does its job alone, so callers never
// wait for each other and a job's work is only ever split, never changed.

namespace kinograph::graph {

/// Most workers a job can have (the caller and the pool's threads); WorkerLocal keeps a slot
/// for each.
inline constexpr int kMaxWorkers = 8;

/// The worker running on this thread: 0 on any caller's thread, 1… on the pool's threads.
int current_worker();

/// Runs `body(context, w)` on the calling thread (w = 0) and on up to `workers` − 1 of the
/// pool's threads (w = 1…), and returns how many ran when every call has. Fewer run when the machine has
/// fewer cores, the pool is serving another caller or `workers` ≤ 1: `body` must share out its
/// work dynamically so that worker 0 alone finishes it. An exception thrown by any call is
/// rethrown here (the caller's first, else the first caught), after all calls have returned.
/// Allocates nothing once the pool's threads are started.
using WorkerBody = void (*)(void* context, int worker);
int run_on_workers(int workers, WorkerBody body, void* context);

/// The same for a callable `body(int worker)`.
template <class F>
int run_on_workers(int workers, F& body) {
  return run_on_workers(
      workers, [](void* c, int w) { (*static_cast<F*>(c))(w); }, &body);
}

}  // namespace kinograph::graph

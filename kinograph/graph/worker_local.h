#pragma once
// A workspace shared by the factors of one graph, one copy per worker (worker_pool.h), so that
// factors sharing it may be evaluated on several threads at once.
#include <array>
#include <functional>
#include <memory>
#include <utility>

#include "kinograph/graph/worker_pool.h"

namespace kinograph::graph {

/// One T per worker, each made by `make` when its worker first asks. A slot is only ever
/// touched by its own worker, so no locking is needed; one graph must not be evaluated by two
/// callers at once (as for any workspace).
template <class T>
class WorkerLocal {
 public:
  explicit WorkerLocal(std::function<std::unique_ptr<T>()> make) : make_(std::move(make)) {
    slots_[0] = make_();  // the caller's, at once: most graphs never see another worker
  }
  /// The calling worker's T.
  T& local() {
    std::unique_ptr<T>& slot = slots_[static_cast<size_t>(current_worker())];
    if (!slot) slot = make_();
    return *slot;
  }
  /// Calls f(T&) on every T made so far; only while no worker is at work on them.
  template <class F>
  void for_each(F&& f) {
    for (std::unique_ptr<T>& slot : slots_) {
      if (slot) f(*slot);
    }
  }

 private:
  std::function<std::unique_ptr<T>()> make_;
  std::array<std::unique_ptr<T>, kMaxWorkers> slots_;
};

}  // namespace kinograph::graph

#include "kinograph/graph/worker_pool.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace kinograph::graph {
namespace {

thread_local int t_worker = 0;
thread_local bool t_in_job = false;  // a job (or a pool thread) runs here: no nested jobs

// Sets a flag for the lifetime of the guard.
struct FlagGuard {
  explicit FlagGuard(bool& flag) : flag_(flag) { flag_ = true; }
  ~FlagGuard() { flag_ = false; }
  FlagGuard(const FlagGuard&) = delete;
  FlagGuard& operator=(const FlagGuard&) = delete;
  bool& flag_;
};

// Spins the CPU briefly (a pause instruction where there is one).
inline void relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#else
  std::this_thread::yield();
#endif
}

// Spins until `done()` or `budget` has passed; returns done().
template <class Done>
bool spin_until(Done done, std::chrono::microseconds budget) {
  const auto end = std::chrono::steady_clock::now() + budget;
  for (int i = 1;; ++i) {
    if (done()) return true;
    relax();
    if (i % 64 == 0 && std::chrono::steady_clock::now() > end) return done();
  }
}

// How long a pool thread waits for the next job before it sleeps, and the caller for the pool
// threads to finish before it sleeps: a solver's linearizations come a factorization apart, and
// waking a sleeping thread costs tens of microseconds.
constexpr std::chrono::microseconds kIdleSpin{250};
constexpr std::chrono::microseconds kFinishSpin{200};

// Threads started on first use and kept for the process's life; one job at a time. A job is
// announced by one atomic word, its number and how many pool threads it wants.
class WorkerPool {
 public:
  static WorkerPool& instance() {
    static WorkerPool pool;
    return pool;
  }

  int run(int workers, WorkerBody body, void* context) {
    // A job inside a job, and any job of a forked child (which has none of the parent's
    // threads), runs alone.
    if (workers <= 1 || t_in_job || getpid() != pid_) {
      body(context, 0);
      return 1;
    }
    const FlagGuard in_job(t_in_job);
    std::unique_lock<std::mutex> serving(serving_, std::try_to_lock);
    if (!serving.owns_lock()) {
      body(context, 0);
      return 1;
    }
    start_threads();
    const int helpers = std::min<int>(workers - 1, static_cast<int>(threads_.size()));
    if (helpers == 0) {
      body(context, 0);
      return 1;
    }
    job_ = body;
    context_ = context;
    error_ = nullptr;
    running_.store(helpers, std::memory_order_relaxed);
    {
      std::lock_guard<std::mutex> lock(mutex_);  // a thread about to sleep sees it or is woken
      const uint64_t next = (announced_.load(std::memory_order_relaxed) >> 8) + 1;
      announced_.store(next << 8 | static_cast<uint64_t>(helpers), std::memory_order_release);
    }
    wake_.notify_all();
    std::exception_ptr own;
    try {
      body(context, 0);
    } catch (...) {
      own = std::current_exception();
    }
    const auto finished = [this] { return running_.load(std::memory_order_acquire) == 0; };
    if (!spin_until(finished, kFinishSpin)) {
      std::unique_lock<std::mutex> lock(mutex_);
      done_.wait(lock, finished);
    }
    if (!own) own = error_;
    if (own) std::rethrow_exception(own);
    return helpers + 1;
  }

  ~WorkerPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : threads_) {
      if (t.joinable()) t.join();
    }
  }

 private:
  WorkerPool() : pid_(getpid()) {}

  void start_threads() {
    if (started_) return;
    started_ = true;
    const int cores = static_cast<int>(std::thread::hardware_concurrency());
    const int count = std::clamp(cores - 1, 0, kMaxWorkers - 1);
    for (int w = 1; w <= count; ++w) threads_.emplace_back([this, w] { serve(w); });
  }

  void serve(int w) {
    t_worker = w;
    t_in_job = true;
    uint64_t seen = 0;  // started by the first job, which it must not miss
    for (;;) {
      const auto announced = [&] { return announced_.load(std::memory_order_acquire) != seen; };
      if (!spin_until(announced, kIdleSpin)) {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || announced(); });
        if (stop_) return;
      }
      seen = announced_.load(std::memory_order_acquire);
      if (w > static_cast<int>(seen & 0xff)) continue;  // not wanted for this job
      std::exception_ptr error;
      try {
        job_(context_, w);
      } catch (...) {
        error = std::current_exception();
      }
      if (error) {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!error_) error_ = error;
      }
      if (running_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
        std::lock_guard<std::mutex> lock(mutex_);
        done_.notify_one();
      }
    }
  }

  const pid_t pid_;
  std::mutex serving_;  // held by the caller whose job runs
  bool started_ = false;
  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  // The job: set by its caller before it is announced, read by the threads it wants.
  WorkerBody job_ = nullptr;
  void* context_ = nullptr;
  std::exception_ptr error_;  // under mutex_
  std::atomic<uint64_t> announced_{0};  // job number << 8 | pool threads wanted
  std::atomic<int> running_{0};         // wanted pool threads not yet done
  bool stop_ = false;                   // under mutex_
};

}  // namespace

int current_worker() { return t_worker; }

int run_on_workers(int workers, WorkerBody body, void* context) {
  return WorkerPool::instance().run(workers, body, context);
}

}  // namespace kinograph::graph

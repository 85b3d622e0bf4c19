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

#include "kinograph/graph/cancellation.h"

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
// one atomic word: its number, the pool threads it wants, whether it is closed, how many
// threads joined and how many finished. The caller closes its job when its own share is done
// and waits only for the threads that joined by then: a thread the machine has not run yet
// (another process has the core) never holds the caller up.
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
    cancel_ = cancellation_flag();
    error_ = nullptr;
    {
      std::lock_guard<std::mutex> lock(mutex_);  // a thread about to sleep sees it or is woken
      ++job_number_;
      state_.store(job_number_ << kJobShift | static_cast<uint64_t>(helpers) << kWantedShift,
                   std::memory_order_release);
    }
    wake_.notify_all();
    std::exception_ptr own;
    try {
      body(context, 0);
    } catch (...) {
      own = std::current_exception();
    }
    const uint64_t closed = state_.fetch_or(kClosed, std::memory_order_acq_rel) | kClosed;
    const uint64_t joined = closed & kCountMask;
    const auto finished = [&] {
      return (state_.load(std::memory_order_acquire) >> kFinishedShift & kCountMask) == joined;
    };
    if (!spin_until(finished, kFinishSpin)) {
      std::unique_lock<std::mutex> lock(mutex_);
      done_.wait(lock, finished);
    }
    if (!own) {
      std::lock_guard<std::mutex> lock(mutex_);
      own = error_;
    }
    if (own) std::rethrow_exception(own);
    return static_cast<int>(joined) + 1;
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
  static constexpr int kJobShift = 32, kWantedShift = 24, kFinishedShift = 8;
  static constexpr uint64_t kClosed = uint64_t{1} << 16, kCountMask = 0xff;

  WorkerPool() : pid_(getpid()) {}

  void start_threads() {
    if (started_) return;
    started_ = true;
    const int cores = static_cast<int>(std::thread::hardware_concurrency());
    const int count = std::clamp(cores - 1, 0, kMaxWorkers - 1);
    for (int w = 1; w <= count; ++w) threads_.emplace_back([this, w] { serve(w); });
  }

  // Joins the announced job `job` unless it is closed, taken over by the next or does not want
  // thread w.
  bool join(uint64_t job, int w) {
    uint64_t s = state_.load(std::memory_order_acquire);
    while (s >> kJobShift == job && !(s & kClosed) &&
           w <= static_cast<int>(s >> kWantedShift & kCountMask)) {
      if (state_.compare_exchange_weak(s, s + 1, std::memory_order_acq_rel)) return true;
    }
    return false;
  }

  void serve(int w) {
    t_worker = w;
    t_in_job = true;
    uint64_t seen = 0;  // the last job looked at; the first is 1
    for (;;) {
      const auto announced = [&] {
        return state_.load(std::memory_order_acquire) >> kJobShift != seen;
      };
      if (!spin_until(announced, kIdleSpin)) {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || announced(); });
        if (stop_) return;
      }
      seen = state_.load(std::memory_order_acquire) >> kJobShift;
      if (!join(seen, w)) continue;
      std::exception_ptr error;
      try {
        if (cancel_ != nullptr) {  // the caller's cancellation reaches its helpers
          const CancellationScope scope(*cancel_);
          job_(context_, w);
        } else {
          job_(context_, w);
        }
      } catch (...) {
        error = std::current_exception();
      }
      if (error) {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!error_) error_ = error;
      }
      const uint64_t s =
          state_.fetch_add(uint64_t{1} << kFinishedShift, std::memory_order_acq_rel) +
          (uint64_t{1} << kFinishedShift);
      if ((s & kClosed) && (s >> kFinishedShift & kCountMask) == (s & kCountMask)) {
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
  // The job: set by its caller before it is announced, read by the threads that join it.
  WorkerBody job_ = nullptr;
  void* context_ = nullptr;
  const std::atomic<bool>* cancel_ = nullptr;  // the caller's cancellation flag, if any
  std::exception_ptr error_;  // under mutex_
  uint64_t job_number_ = 0;   // under serving_
  // job number << 32 | wanted << 24 | closed << 16 | finished << 8 | joined
  std::atomic<uint64_t> state_{0};
  bool stop_ = false;  // under mutex_
};

}  // namespace

int current_worker() { return t_worker; }

int run_on_workers(int workers, WorkerBody body, void* context) {
  return WorkerPool::instance().run(workers, body, context);
}

}  // namespace kinograph::graph

#pragma once
// Wall time of a solver's phases, on the steady clock.
#include <chrono>

namespace kinograph::graph {

/// Seconds elapsed on the steady clock since `t`.
inline double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

/// Adds the wall time of its own lifetime to `total`: a phase timed across all of its exits.
class ScopedTimer {
 public:
  explicit ScopedTimer(double& total) : total_(total), t0_(std::chrono::steady_clock::now()) {}
  ~ScopedTimer() { total_ += seconds_since(t0_); }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  double& total_;
  std::chrono::steady_clock::time_point t0_;
};

}  // namespace kinograph::graph

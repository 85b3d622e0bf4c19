#pragma once
// Wall time of a solver's phases, on the steady clock.
#include <chrono>

namespace kinograph::graph {

/// Seconds elapsed on the steady clock since `t`.
inline double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace kinograph::graph

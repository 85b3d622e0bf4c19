#pragma once
// CPU time of the benchmark process: on a shared machine it moves far less than the wall clock
// (a single-threaded benchmark's CPU time is its own work, whatever else runs).
#include <ctime>

namespace kinograph::bench {

/// This process's CPU time in seconds (user + system, all threads).
inline double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

}  // namespace kinograph::bench

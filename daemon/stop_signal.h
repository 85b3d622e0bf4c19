#pragma once
// A stop request that a signal handler can make: it sets a flag and wakes, through an eventfd,
// the poll() that waits for LCM traffic, so that the node stops at once instead of at the end
// of its next wait (kinographd's SIGTERM/SIGINT).
#include <atomic>

namespace kinograph::daemon {

/// A flag plus an eventfd that becomes readable when the flag is set.
class StopSignal {
 public:
  /// Throws std::system_error when no eventfd can be made.
  StopSignal();
  ~StopSignal();
  StopSignal(const StopSignal&) = delete;
  StopSignal& operator=(const StopSignal&) = delete;

  /// Sets the flag and wakes fd(); async-signal-safe (an atomic store and a write()).
  void request() noexcept;
  /// The flag, for PlannerNode::run.
  const std::atomic<bool>& flag() const { return flag_; }
  /// Readable once request() was called: poll it together with the LCM file descriptor.
  int fd() const { return fd_; }

 private:
  std::atomic<bool> flag_{false};
  int fd_ = -1;
};

}  // namespace kinograph::daemon

#pragma once
// Cooperative cancellation of the solvers: a thread that may have to stop a solve under way (a
// daemon asked to shut down) installs a flag with a CancellationScope, and the solver loops
// (LevenbergMarquardt, GaussNewton, ISAM2::update) call throw_if_cancelled() once per
// iteration. So do the long walks of a plan outside them: the detour ranking's segments, the
// path search's collision queries and the validator's collision walk. The flag is per thread
// so that no planner option or signature carries it.
#include <atomic>

namespace kinograph::graph {

/// Thrown by throw_if_cancelled(). Deliberately not a std::exception: the planners turn a
/// std::exception from a solve into a failed plan, and a cancellation must reach the caller
/// that asked for it through all of them.
struct Cancelled {};

/// Installs `flag` as this thread's cancellation flag while the scope lives (scopes nest; the
/// previous flag is restored). The flag must outlive the scope.
class CancellationScope {
 public:
  explicit CancellationScope(const std::atomic<bool>& flag);
  ~CancellationScope();
  CancellationScope(const CancellationScope&) = delete;
  CancellationScope& operator=(const CancellationScope&) = delete;

 private:
  const std::atomic<bool>* previous_;
};

/// Throws Cancelled when this thread's flag (if any) is set. Call only where the solver's state
/// is consistent (between iterations), so that the object can be destroyed or reused.
void throw_if_cancelled();

/// This thread's flag, null when none is installed: the worker pool installs the caller's flag
/// on the threads that help it, so that a cancellation stops their share of a job too.
const std::atomic<bool>* cancellation_flag();

}  // namespace kinograph::graph

#pragma once
// Where a robot without measured states is: along the valid plans its daemon published, on the
// common clock. Each plan is in force from its start until a newer one starts, so a replan starts
// where the motion under way has the robot, not back at the scene's start (docs/multi_robot.md).
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>

#include "kinograph/dynamics/model.h"
#include "kinograph/execution/plan_schedule.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/trajectory_sampler.h"

namespace kinograph::daemon {

/// The motion a daemon's published plans describe, for a robot whose state is never measured.
/// Not thread-safe.
class PlannedMotion {
 public:
  /// Plans remembered: a plan waiting to start keeps the ones before it in force until then, and
  /// a daemon waits at most once per neighbour (at most 16).
  static constexpr std::size_t kMemory = 32;

  /// Borrows `model`, which must outlive this.
  explicit PlannedMotion(const dynamics::Model& model) : model_(model) {}

  /// A valid plan was published: from its start_utime on, the robot follows it.
  void published(execution::TimedPlan plan);
  /// Where the robot is at `utime` (q, q̇ on the plan's interpolant): the newest plan started by
  /// then, at its last knot once it ended; before every plan, the oldest one's first knot. Empty
  /// before any plan was published.
  std::optional<execution::Setpoint> at(int64_t utime);
  /// The motion from `utime` on at the knots of a plan of `steps` intervals over `horizon` s:
  /// the plans in force continued (held at the last one's end), the natural warm start of a plan
  /// from at(utime). Empty before any plan was published.
  std::optional<planning::Plan> ahead(int64_t utime, double horizon, int steps);
  /// A knot of the newest plan: its index and its time on the common clock.
  struct Knot {
    int index = 0;
    int64_t utime = 0;
  };
  /// The newest plan's first knot at or after `utime`, when that plan has started by `utime`
  /// and has a knot left: where a replan that goes on from the plan's own knots can start.
  std::optional<Knot> knot_from(int64_t utime) const;
  /// True once a plan was published.
  bool moving() const { return !plans_.empty(); }

 private:
  struct Held {
    std::unique_ptr<execution::TimedPlan> timed;  // on the heap: the sampler borrows its plan
    std::unique_ptr<planning::TrajectorySampler> sampler;
  };
  const dynamics::Model& model_;
  std::deque<Held> plans_;  // in the order published
};

}  // namespace kinograph::daemon

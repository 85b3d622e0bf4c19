#pragma once
// Plans on the robot's clock, as an executor follows them: each plan takes over from the one
// before at its take-over time, is read through the one interpolant (TrajectorySampler) in
// between, and its last knot is held once it ends.
#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "kinograph/dynamics/model.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/trajectory_sampler.h"

namespace kinograph::execution {

/// A plan placed on the robot's clock: knot k is at start_utime + t[k]·10⁶ µs, and the plan
/// replaces the one before it at takeover_utime (plan_t's clock fields).
struct TimedPlan {
  int64_t plan_id = -1;        ///< -1: not a planner's plan (a stopping trajectory)
  int64_t start_utime = 0;     ///< µs, robot clock
  int64_t takeover_utime = 0;  ///< µs, robot clock
  int64_t state_utime = -1;    ///< the measured state it was planned from; -1 = none
  planning::Plan plan;
};

/// What the robot is told to do at one time: q, q̇, q̈ and the feed-forward τ, model order.
struct Setpoint {
  int64_t utime = 0;
  int64_t plan_id = -1;
  Eigen::VectorXd q, qd, qdd, tau;
};

/// One take-over: at `utime` the plan `to` replaced `from`, and how far apart the two plans are
/// there (max over joints): the discontinuity of the commanded motion, 0 for a replan that
/// joins. `utime` is the plan's take-over time, or the time of the last setpoint of `from` when
/// the plan arrived after its take-over time.
struct Takeover {
  int64_t utime = 0;
  int64_t from = -1, to = -1;
  double jump_q = 0;   ///< rad
  double jump_qd = 0;  ///< rad/s
};

/// `timed` at robot time `utime` (µs) read through `sampler` (a sampler of timed.plan): knot 0
/// before the plan's start, the interpolant in between, the last knot exactly after the end.
Setpoint sample_at(const TimedPlan& timed, planning::TrajectorySampler& sampler, int64_t utime);

/// The plan in force and those queued to take over, for one robot. Not thread-safe.
class PlanSchedule {
 public:
  /// Borrows `model`, which must outlive the schedule.
  explicit PlanSchedule(const dynamics::Model& model);

  /// Queues `plan` to take over at its takeover_utime. A queued plan that would take over at
  /// the same time or later is dropped (the newer plan knows more). Throws
  /// std::invalid_argument when the plan cannot be sampled (TrajectorySampler's reasons).
  void add(TimedPlan plan);
  /// Drops the plan in force and every queued one: at() has no setpoint until the next add().
  void clear();

  /// The setpoint at `utime`: first the newest queued plan due by then takes over (recorded in
  /// takeovers()), then the plan in force is sampled there; before knot 0 it reads knot 0 and
  /// after the last knot it holds that knot. Empty while no plan is in force.
  std::optional<Setpoint> at(int64_t utime);

  /// The plan in force (-1 for a stopping trajectory); nullopt when none.
  std::optional<int64_t> current_plan_id() const;
  /// Every take-over so far, oldest first.
  const std::vector<Takeover>& takeovers() const { return takeovers_; }

 private:
  // A plan with the sampler that reads it (which borrows the plan: both stay put on the heap).
  struct Entry {
    TimedPlan timed;
    std::unique_ptr<planning::TrajectorySampler> sampler;
  };

  const dynamics::Model& model_;
  std::unique_ptr<Entry> current_;
  std::deque<std::unique_ptr<Entry>> queued_;  // ascending takeover_utime
  std::vector<Takeover> takeovers_;
  int64_t last_utime_ = std::numeric_limits<int64_t>::min();  // latest time at() was asked
};

}  // namespace kinograph::execution

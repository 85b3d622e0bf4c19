#pragma once
// Replans that join the motion under way. While an executor follows the daemon's plans (its
// joint_command_t name one of them), a replan starts where the plan in force will be when the
// replan takes over, at the latest state's time plus the expected planning latency, so that the
// commanded q and q̇ are continuous at the switch (docs/execution.md).
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>

#include "kinograph/dynamics/model.h"
#include "kinograph/execution/plan_schedule.h"
#include "kinograph/planning/trajectory_sampler.h"

namespace kinograph::daemon {

/// Where a replan takes over from the plan in force, on the robot's clock.
struct JoinPoint {
  int64_t takeover_utime = 0;  ///< µs: knot 0 of the replan and its take-over
  int64_t from_plan = -1;      ///< the plan it continues
  Eigen::VectorXd q, qd;       ///< that plan sampled at the take-over
};

/// The daemon's newest valid plan and whether an executor follows it. Not thread-safe.
class MotionJoin {
 public:
  /// Borrows `model`, which must outlive this. `latency_s`: the expected time (robot clock)
  /// from the latest state to the replan being in the executor's hands.
  MotionJoin(const dynamics::Model& model, double latency_s);

  /// A valid plan was published: it is the plan in force from its take-over.
  void published(execution::TimedPlan plan);
  /// An executor commanded a setpoint of plan `plan_id` (−1: none, e.g. a stop) at `utime`.
  void commanded(int64_t plan_id, int64_t utime);

  /// Where a replan from the state at `state_utime` joins the motion: empty (plan from the
  /// measured state) unless an executor's latest command, at most `max_command_age_s` older
  /// than the state, follows a plan this daemon published. The take-over is state_utime +
  /// latency, and after the last plan's take-over; past that plan's end, its last knot.
  std::optional<JoinPoint> join(int64_t state_utime, double max_command_age_s);

  /// The expected latency (s, robot clock).
  double latency_s() const { return latency_s_; }

 private:
  const dynamics::Model& model_;
  double latency_s_;
  int64_t first_plan_id_ = -1;                  // to recognise commands of this daemon's plans
  std::unique_ptr<execution::TimedPlan> plan_;  // the newest valid plan, on the heap: the
  std::unique_ptr<planning::TrajectorySampler> sampler_;  // sampler borrows it
  int64_t command_plan_id_ = -1, command_utime_ = 0;
  bool commanded_ = false;
};

}  // namespace kinograph::daemon

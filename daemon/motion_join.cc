#include "daemon/motion_join.h"

#include <algorithm>
#include <cmath>

namespace kinograph::daemon {

MotionJoin::MotionJoin(const dynamics::Model& model, double latency_s)
    : model_(model), latency_s_(latency_s) {}

void MotionJoin::published(execution::TimedPlan plan) {
  auto copy = std::make_unique<execution::TimedPlan>(std::move(plan));
  sampler_ = std::make_unique<planning::TrajectorySampler>(model_, copy->plan);
  if (first_plan_id_ < 0) first_plan_id_ = copy->plan_id;
  plan_ = std::move(copy);
}

void MotionJoin::commanded(int64_t plan_id, int64_t utime) {
  command_plan_id_ = plan_id;
  command_utime_ = utime;
  commanded_ = true;
}

std::optional<JoinPoint> MotionJoin::join(int64_t state_utime, double max_command_age_s) {
  if (!plan_ || !commanded_) return std::nullopt;
  if (command_plan_id_ < first_plan_id_ || command_plan_id_ > plan_->plan_id) return std::nullopt;
  if (static_cast<double>(state_utime - command_utime_) * 1e-6 > max_command_age_s) {
    return std::nullopt;
  }
  JoinPoint join;
  join.from_plan = plan_->plan_id;
  join.takeover_utime =
      std::max<int64_t>(state_utime + std::llround(latency_s_ * 1e6), plan_->takeover_utime + 1);
  const execution::Setpoint s = execution::sample_at(*plan_, *sampler_, join.takeover_utime);
  join.q = s.q;
  join.qd = s.qd;
  return join;
}

}  // namespace kinograph::daemon

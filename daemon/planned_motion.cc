#include "daemon/planned_motion.h"

#include <cmath>

namespace kinograph::daemon {

void PlannedMotion::published(execution::TimedPlan plan) {
  Held h;
  h.timed = std::make_unique<execution::TimedPlan>(std::move(plan));
  h.sampler = std::make_unique<planning::TrajectorySampler>(model_, h.timed->plan);
  plans_.push_back(std::move(h));
  if (plans_.size() > kMemory) plans_.pop_front();
}

std::optional<execution::Setpoint> PlannedMotion::at(int64_t utime) {
  if (plans_.empty()) return std::nullopt;
  // A newer plan replaces every older one from its start on.
  for (auto it = plans_.rbegin(); it != plans_.rend(); ++it) {
    if (it->timed->start_utime <= utime)
      return execution::sample_at(*it->timed, *it->sampler, utime);
  }
  Held& oldest = plans_.front();
  return execution::sample_at(*oldest.timed, *oldest.sampler, utime);
}

std::optional<PlannedMotion::Knot> PlannedMotion::knot_from(int64_t utime) const {
  if (plans_.empty() || plans_.back().timed->start_utime > utime) return std::nullopt;
  const execution::TimedPlan& newest = *plans_.back().timed;
  for (std::size_t k = 0; k < newest.plan.t.size(); ++k) {
    const int64_t at = newest.start_utime + std::llround(newest.plan.t[k] * 1e6);
    if (at >= utime) return Knot{static_cast<int>(k), at};
  }
  return std::nullopt;
}

std::optional<planning::Plan> PlannedMotion::ahead(int64_t utime, double horizon, int steps) {
  if (plans_.empty() || steps < 1) return std::nullopt;
  planning::Plan p;
  const int n = model_.nq();
  p.q.resize(steps + 1, n);
  p.qd.resize(steps + 1, n);
  p.qdd.resize(steps + 1, n);
  p.tau.resize(steps + 1, n);
  for (int k = 0; k <= steps; ++k) {
    const double t = horizon * k / steps;
    p.t.push_back(t);
    const execution::Setpoint s = *at(utime + std::llround(t * 1e6));
    p.q.row(k) = s.q.transpose();
    p.qd.row(k) = s.qd.transpose();
    p.qdd.row(k) = s.qdd.transpose();
    p.tau.row(k) = s.tau.transpose();
  }
  return p;
}

}  // namespace kinograph::daemon

#include "kinograph/execution/plan_schedule.h"

#include <algorithm>

namespace kinograph::execution {

PlanSchedule::PlanSchedule(const dynamics::Model& model) : model_(model) {}

void PlanSchedule::add(TimedPlan plan) {
  auto entry = std::make_unique<Entry>();
  entry->timed = std::move(plan);
  entry->sampler = std::make_unique<planning::TrajectorySampler>(model_, entry->timed.plan);
  const int64_t takeover = entry->timed.takeover_utime;
  while (!queued_.empty() && queued_.back()->timed.takeover_utime >= takeover) queued_.pop_back();
  queued_.push_back(std::move(entry));
}

void PlanSchedule::clear() {
  current_.reset();
  queued_.clear();
}

std::optional<int64_t> PlanSchedule::current_plan_id() const {
  if (!current_) return std::nullopt;
  return current_->timed.plan_id;
}

Setpoint sample_at(const TimedPlan& timed, planning::TrajectorySampler& sampler, int64_t utime) {
  const planning::Plan& plan = timed.plan;
  const double t = static_cast<double>(utime - timed.start_utime) * 1e-6;
  Setpoint s;
  s.utime = utime;
  s.plan_id = timed.plan_id;
  if (t >= plan.t.back()) {
    // The plan's end is its goal at rest: hold that knot exactly.
    const Eigen::Index last = plan.q.rows() - 1;
    s.q = plan.q.row(last).transpose();
    s.qd = plan.qd.row(last).transpose();
    s.qdd = plan.qdd.row(last).transpose();
    s.tau = plan.tau.row(last).transpose();
    return s;
  }
  const planning::InterpolantPoint p = sampler.at(plan.t.front() + std::max(t, 0.0));
  s.q = p.q;
  s.qd = p.qd;
  s.qdd = p.qdd;
  s.tau = p.tau;
  return s;
}

std::optional<Setpoint> PlanSchedule::at(int64_t utime) {
  std::unique_ptr<Entry> due;
  while (!queued_.empty() && queued_.front()->timed.takeover_utime <= utime) {
    due = std::move(queued_.front());
    queued_.pop_front();
  }
  if (due) {
    // The commanded motion switches at the take-over time, or now if the plan came too late.
    Takeover switch_;
    switch_.utime = std::max(due->timed.takeover_utime, last_utime_);
    switch_.to = due->timed.plan_id;
    if (current_) {
      switch_.from = current_->timed.plan_id;
      const Setpoint before = sample_at(current_->timed, *current_->sampler, switch_.utime);
      const Setpoint after = sample_at(due->timed, *due->sampler, switch_.utime);
      switch_.jump_q = (after.q - before.q).cwiseAbs().maxCoeff();
      switch_.jump_qd = (after.qd - before.qd).cwiseAbs().maxCoeff();
    }
    takeovers_.push_back(switch_);
    current_ = std::move(due);
  }
  last_utime_ = std::max(last_utime_, utime);
  if (!current_) return std::nullopt;
  return sample_at(current_->timed, *current_->sampler, utime);
}

}  // namespace kinograph::execution

#include "kinograph/execution/robot_clock.h"

#include <algorithm>
#include <cmath>

namespace kinograph::execution {

void RobotClock::observe(int64_t utime, double wall_s) {
  // A clock that jumps back (a restarted simulator) starts the estimate afresh.
  if (!states_.empty() && utime < states_.back().first) {
    states_.clear();
    returned_ = false;
  }
  states_.emplace_back(utime, wall_s);
  while (states_.size() > 2 && wall_s - states_.front().second > kWindowS) states_.pop_front();
}

double RobotClock::rate() const {
  if (states_.size() < 2) return 1.0;
  const double span = states_.back().second - states_.front().second;
  if (span < kMinSpanS) return 1.0;
  // Bounded as a simulator's --slowdown is, so that a frozen clock never stops the estimate.
  return std::clamp(static_cast<double>(states_.back().first - states_.front().first) * 1e-6 / span,
                    1e-3, 1e3);
}

std::optional<int64_t> RobotClock::now(double wall_s) {
  if (states_.empty()) return std::nullopt;
  const auto& [utime, arrived] = states_.back();
  const double ahead_us = std::max(0.0, wall_s - arrived) * rate() * 1e6;
  int64_t t = utime + std::min(kMaxAheadUs, static_cast<int64_t>(std::llround(ahead_us)));
  if (returned_) t = std::max(t, last_returned_);
  last_returned_ = t;
  returned_ = true;
  return t;
}

}  // namespace kinograph::execution

#pragma once
// The robot's clock as seen from a process that only receives its states: the latest state's
// time, carried forward between states at the rate the robot's clock runs against the wall
// clock (1 for a real robot, 0.1 for a simulator ten times slower than real time).
#include <cstdint>
#include <deque>
#include <optional>
#include <utility>

namespace kinograph::execution {

/// Estimates the robot's clock from the utimes of its states and the wall times they arrived.
class RobotClock {
 public:
  /// The rate is measured over the states of the last kWindowS wall seconds, once they span at
  /// least kMinSpanS (before that the robot's clock is taken to run at the wall clock's rate).
  static constexpr double kWindowS = 2.0;
  static constexpr double kMinSpanS = 0.2;
  /// Longest the clock is carried forward past the latest state (µs of robot time): if the
  /// states stop, setpoints stop advancing instead of running ahead of the robot.
  static constexpr int64_t kMaxAheadUs = 20'000;

  /// A state stamped `utime` (µs, robot clock) arrived at wall time `wall_s` (s, monotonic).
  void observe(int64_t utime, double wall_s);
  /// The robot's clock at wall time `wall_s`, never earlier than a time returned before;
  /// empty before the first state.
  std::optional<int64_t> now(double wall_s);
  /// Robot seconds per wall second, as measured (1 until measurable), within [10⁻³, 10³].
  double rate() const;

 private:
  std::deque<std::pair<int64_t, double>> states_;  // (utime, wall_s), oldest first
  int64_t last_returned_ = 0;
  bool returned_ = false;
};

}  // namespace kinograph::execution

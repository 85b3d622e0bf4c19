// The robot's clock read from its states: the latest state's time, carried forward at the rate
// the states' clock runs against the wall (measured), never backwards, never far past the
// latest state.
#include "kinograph/execution/robot_clock.h"

#include <gtest/gtest.h>

namespace kinograph::execution {
namespace {

TEST(RobotClock, EmptyBeforeAnyState) {
  RobotClock clock;
  EXPECT_FALSE(clock.now(0.0).has_value());
}

TEST(RobotClock, MeasuresASimulatorTenTimesSlower) {
  RobotClock clock;
  // States 5 ms apart on the robot's clock, 50 ms apart on the wall clock, for 1 s.
  for (int i = 0; i <= 20; ++i) clock.observe(5'000'000 + i * 5'000, 100.0 + i * 0.05);
  EXPECT_NEAR(clock.rate(), 0.1, 1e-12);
  // 30 ms of wall after the last state is 3 ms of robot time.
  EXPECT_EQ(*clock.now(101.0 + 0.03), 5'100'000 + 3'000);
}

TEST(RobotClock, TakesTheWallRateUntilMeasurable) {
  RobotClock clock;
  clock.observe(1'000'000, 10.0);
  clock.observe(1'000'500, 10.01);  // spans less than kMinSpanS
  EXPECT_EQ(clock.rate(), 1.0);
  EXPECT_EQ(*clock.now(10.015), 1'000'500 + 5'000);
}

TEST(RobotClock, NeverRunsFarAheadOfTheLatestState) {
  RobotClock clock;
  clock.observe(0, 0.0);
  EXPECT_EQ(*clock.now(5.0), RobotClock::kMaxAheadUs);
}

TEST(RobotClock, NeverGoesBackwards) {
  RobotClock clock;
  clock.observe(0, 0.0);
  const int64_t ahead = *clock.now(0.015);  // 15 ms carried forward
  EXPECT_EQ(ahead, 15'000);
  clock.observe(10'000, 0.016);  // the robot was slower than the estimate
  EXPECT_EQ(*clock.now(0.016), ahead);
}

TEST(RobotClock, StartsAfreshWhenTheRobotsClockJumpsBack) {
  RobotClock clock;
  clock.observe(9'000'000, 0.0);
  EXPECT_EQ(*clock.now(0.0), 9'000'000);
  clock.observe(1'000, 1.0);  // a restarted simulator
  EXPECT_EQ(*clock.now(1.0), 1'000);
}

}  // namespace
}  // namespace kinograph::execution

// The incremental planner's stopping rule: when an update's objective counts as settled.
#include "kinograph/planning/incremental/stopping_rule.h"

#include <gtest/gtest.h>

namespace kinograph::planning {
namespace {

constexpr double kTolerance = 1e-3;

TEST(StoppingRule, AcceptsAnObjectiveWithinItsBandOfThePreviousUpdate) {
  StoppingRule rule(kTolerance, 100, /*stop_at_first_valid=*/true);
  EXPECT_TRUE(rule.accept(97));    // fell by 3 %
  EXPECT_FALSE(rule.accept(90));   // fell by more than 5 %: still falling
  EXPECT_TRUE(rule.accept(130));   // rose by less than 50 %
  EXPECT_FALSE(rule.accept(200));  // a jump
  EXPECT_TRUE(rule.accept(210));   // settled where the jump led
}

TEST(StoppingRule, AfterAJumpTheObjectiveBeforeItIsAReferenceToo) {
  StoppingRule rule(kTolerance, 60, true);
  EXPECT_FALSE(rule.accept(280));  // a jump from 60
  EXPECT_TRUE(rule.accept(62));    // far below the jump, but settled against 60
  EXPECT_FALSE(rule.accept(50));   // and the reference is the last update again
}

TEST(StoppingRule, JumpsInARowKeepTheObjectiveBeforeTheFirst) {
  StoppingRule rule(kTolerance, 60, true);
  EXPECT_FALSE(rule.accept(100));  // jump
  EXPECT_FALSE(rule.accept(400));  // another
  EXPECT_TRUE(rule.accept(65));
}

TEST(StoppingRule, WithoutStopAtFirstValidNothingIsAccepted) {
  StoppingRule rule(kTolerance, 100, false);
  EXPECT_FALSE(rule.accept(100));
  EXPECT_FALSE(rule.accept(100));
}

}  // namespace
}  // namespace kinograph::planning

// The daemon's intake: coalescing keeps the newest goal and lists every one it replaced, a
// replace_all discards older obstacle changes, and goal-id gaps are found (and only real ones).
#include "daemon/intake.h"

#include <gtest/gtest.h>

namespace kinograph::daemon {
namespace {

Intake goal(int64_t id) {
  Intake in;
  in.goal.emplace();
  in.goal->goal_id = id;
  return in;
}

Intake obstacle(const std::string& id, bool replace_all = false) {
  Intake in;
  in.obstacles.emplace_back();
  in.obstacles.back().id = id;
  in.replace_all = replace_all;
  return in;
}

TEST(Intake, TheNewestGoalWinsAndEveryOlderOneIsListedOnce) {
  Intake held;
  EXPECT_TRUE(held.empty());
  for (int64_t id = 1; id <= 3; ++id) held.absorb(goal(id));
  Intake later = goal(4);
  later.absorb(goal(5));
  held.absorb(std::move(later));
  ASSERT_TRUE(held.goal);
  EXPECT_EQ(held.goal->goal_id, 5);
  EXPECT_EQ(held.superseded, (std::vector<int64_t>{1, 2, 3, 4}));
  EXPECT_FALSE(held.empty());
}

TEST(Intake, ObstacleChangesKeepTheirOrderAndReplaceAllStartsOver) {
  Intake held = obstacle("a");
  held.absorb(obstacle("b"));
  ASSERT_EQ(held.obstacles.size(), 2u);
  EXPECT_EQ(held.obstacles[1].id, "b");
  EXPECT_FALSE(held.replace_all);
  held.absorb(obstacle("c", /*replace_all=*/true));
  held.absorb(obstacle("d"));
  ASSERT_EQ(held.obstacles.size(), 2u);
  EXPECT_EQ(held.obstacles[0].id, "c");
  EXPECT_EQ(held.obstacles[1].id, "d");
  EXPECT_TRUE(held.replace_all);
}

TEST(Intake, TheNewestStateIsKeptAndAllAreCounted) {
  Intake held;
  for (int k = 0; k < 3; ++k) {
    Intake s;
    s.state.emplace();
    s.state->utime = k;
    s.states = 1;
    held.absorb(std::move(s));
  }
  ASSERT_TRUE(held.state);
  EXPECT_EQ(held.state->utime, 2);
  EXPECT_EQ(held.states, 3u);
}

TEST(GoalIdSequence, FindsTheIdsSkippedBetweenConsecutiveGoals) {
  GoalIdSequence ids(100);
  EXPECT_FALSE(ids.next(5));  // the first goal has no predecessor
  EXPECT_FALSE(ids.next(6));
  const auto gap = ids.next(10);
  ASSERT_TRUE(gap);
  EXPECT_EQ(gap->first, 7);
  EXPECT_EQ(gap->last, 9);
  EXPECT_EQ(gap->revealed_by, 10);
  EXPECT_EQ(gap->count(), 3);
  EXPECT_FALSE(ids.next(11));
}

TEST(GoalIdSequence, AStepBackOrAHugeJumpIsANewNumberingNotALoss) {
  GoalIdSequence ids(100);
  EXPECT_FALSE(ids.next(50));
  EXPECT_FALSE(ids.next(3));        // a restarted sender
  EXPECT_FALSE(ids.next(3));        // the same id again
  const auto most = ids.next(104);  // 100 ids skipped: the largest gap still taken as a loss
  ASSERT_TRUE(most);
  EXPECT_EQ(most->count(), 100);
  EXPECT_FALSE(ids.next(1000000));        // e.g. a sender numbering by time
  EXPECT_FALSE(ids.next(1000000 + 102));  // 101 skipped
  EXPECT_TRUE(ids.next(1000000 + 104));
}

}  // namespace
}  // namespace kinograph::daemon

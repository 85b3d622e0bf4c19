// The coordination rule: a strict priority order (goal time, then name); higher-priority
// neighbours followed along their plans, the others held; a replan only for the own goal or a
// higher-priority neighbour's change, once per change; and a fleet that settles within N − 1
// rounds after every robot gets a new goal (random goal times and plan churn, seeded).
#include "kinograph/fleet/coordination.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace kinograph::fleet {
namespace {

TEST(Priority, EarlierGoalFirstThenName) {
  const PriorityKey early{100, "zed"}, late{200, "abe"}, tie{100, "amy"};
  EXPECT_TRUE(outranks(early, late));
  EXPECT_FALSE(outranks(late, early));
  EXPECT_TRUE(outranks(tie, early));
  EXPECT_FALSE(outranks(early, tie));
  EXPECT_FALSE(outranks(early, early));
  EXPECT_TRUE(outranks(late, PriorityKey{.robot = "abe"}));  // no goal: last
}

TEST(Coordinate, FollowsHigherNeighboursAndHoldsTheOthers) {
  const PriorityKey own{200, "mid"};
  const std::vector<NeighbourView> n = {{"first", {100, "first"}, 7, false},
                                        {"last", {300, "last"}, 9, false},
                                        {"quiet", {150, "quiet"}, 4, true},
                                        {"planless", {120, "planless"}, std::nullopt, false}};
  const Decision d = coordinate(own, n, {}, true);
  EXPECT_TRUE(d.replan);
  EXPECT_EQ(d.treatment,
            (std::vector<Treatment>{Treatment::kAlongPlan, Treatment::kHeldAtState,
                                    Treatment::kHeldAtState, Treatment::kHeldAtState}));
  EXPECT_EQ(d.around.at("first"), 7);
  EXPECT_EQ(d.around.at("last"), kHeldMark);
  EXPECT_EQ(d.around.at("quiet"), kHeldMark);
}

TEST(Coordinate, ReplansOncePerHigherNeighbourChangeAndNeverForALowerOne) {
  const PriorityKey own{200, "mid"};
  std::vector<NeighbourView> n = {{"high", {100, "high"}, 7, false},
                                  {"low", {300, "low"}, 9, false}};
  PlannedAround planned = coordinate(own, n, {}, true).around;

  n[1].plan_id = 10;  // the lower one replanned: it yields, this robot keeps its plan
  EXPECT_FALSE(coordinate(own, n, planned, false).replan);

  n[0].plan_id = 8;  // the higher one replanned: once
  const Decision d = coordinate(own, n, planned, false);
  EXPECT_TRUE(d.replan);
  EXPECT_NE(d.reason.find("neighbour 'high'"), std::string::npos) << d.reason;
  planned = d.around;
  EXPECT_FALSE(coordinate(own, n, planned, false).replan);

  n[0].silent = true;  // the higher one went silent: held at its last state, one replan
  const Decision silent = coordinate(own, n, planned, false);
  EXPECT_TRUE(silent.replan);
  EXPECT_NE(silent.reason.find("silent"), std::string::npos) << silent.reason;
  EXPECT_FALSE(coordinate(own, n, silent.around, false).replan);
}

TEST(Coordinate, NothingToReplanBeforeTheFirstPlan) {
  const std::vector<NeighbourView> n = {{"high", {100, "high"}, 7, false}};
  const Decision d = coordinate({200, "mid"}, n, {}, false);
  EXPECT_FALSE(d.replan);
}

// Synchronous rounds: every robot decides on the plan ids of the round before; a replan
// publishes a new plan id. After all goals change at once the fleet must be quiet within N − 1
// rounds after the first.
TEST(Coordinate, FleetSettlesWithinNMinusOneRounds) {
  std::mt19937 rng(2026);
  for (int trial = 0; trial < 200; ++trial) {
    const int N = 2 + trial % 7;
    std::uniform_int_distribution<int> goal_time(0, 3);  // ties are common: names decide
    std::vector<PriorityKey> keys(N);
    for (int i = 0; i < N; ++i) keys[i] = {goal_time(rng), "robot" + std::to_string(i)};
    std::vector<std::int64_t> plan(N);
    std::vector<PlannedAround> planned(N);
    std::int64_t next_id = 0;
    std::vector<bool> goal_changed(N, true);
    int last_active = -1;
    for (int round = 0; round < 2 * N + 2; ++round) {
      std::vector<std::int64_t> published = plan;
      bool any = false;
      for (int i = 0; i < N; ++i) {
        std::vector<NeighbourView> views;
        for (int j = 0; j < N; ++j) {
          if (j != i) views.push_back({keys[j].robot, keys[j], plan[j], false});
        }
        const Decision d = coordinate(keys[i], views, planned[i], goal_changed[i]);
        if (d.replan) {
          published[i] = ++next_id;
          planned[i] = d.around;
          any = true;
        }
      }
      std::fill(goal_changed.begin(), goal_changed.end(), false);
      plan = published;
      if (any) last_active = round;
    }
    EXPECT_LE(last_active, N - 1) << "trial " << trial << " with " << N << " robots";
  }
}

TEST(WaitFor, HoldsTheStartUntilTheBlockingPlanEnds) {
  const WaitPlan w = wait_for(2.5, 0.5, 3.0);
  EXPECT_DOUBLE_EQ(w.wait, 2.0);
  EXPECT_DOUBLE_EQ(w.horizon, 5.0);
  const WaitPlan ended = wait_for(1.0, 2.0, 3.0);  // ended before the own start: no wait
  EXPECT_DOUBLE_EQ(ended.wait, 0.0);
  EXPECT_DOUBLE_EQ(ended.horizon, 3.0);
}

TEST(Remedy, WaitsForAFollowedPlanThatEndsLater) {
  const Blocker a{"a", "A", Treatment::kAlongPlan, 2.5, false};
  const Remedy r = remedy("B", a, 0.0, 1.0, "", "overlap");
  EXPECT_EQ(r.kind, Remedy::Kind::kWait);
  EXPECT_DOUBLE_EQ(r.wait.wait, 2.5);
  EXPECT_DOUBLE_EQ(r.wait.horizon, 3.5);
  EXPECT_NE(r.reason.find("neighbour 'a'"), std::string::npos) << r.reason;
}

TEST(Remedy, FailsWhenStillBlockedAfterWaitingOrWhenWaitingIsOff) {
  const Blocker a{"a", "A", Treatment::kAlongPlan, 2.5, false};
  const Remedy after = remedy("B", a, 2.5, 1.0, "", "overlap at the goal");
  EXPECT_EQ(after.kind, Remedy::Kind::kFail);
  EXPECT_NE(after.reason.find("even after waiting 2.500 s"), std::string::npos) << after.reason;
  EXPECT_EQ(blocker_prefix(after.reason), "A");
  const Remedy off = remedy("B", a, 0.0, 1.0, "waiting is off", "overlap");
  EXPECT_EQ(off.kind, Remedy::Kind::kFail);
  EXPECT_NE(off.reason.find("waiting is off"), std::string::npos) << off.reason;
}

TEST(Remedy, AHeldNeighbourBlockedByThisRobotIsADeadlockNamingBoth) {
  Blocker b{"right", "RIGHT", Treatment::kHeldAtState, 0.0, false};
  const Remedy blocked = remedy("LEFT", b, 0.0, 3.0, "", "goal overlaps it");
  EXPECT_EQ(blocked.kind, Remedy::Kind::kFail);
  EXPECT_EQ(blocked.reason.find("deadlock"), std::string::npos) << blocked.reason;
  EXPECT_EQ(blocker_prefix(blocked.reason), "RIGHT");
  b.blocked_by_own = true;  // its answer says it is blocked by LEFT
  const Remedy dead = remedy("LEFT", b, 0.0, 3.0, "", "goal overlaps it");
  EXPECT_EQ(dead.kind, Remedy::Kind::kDeadlock);
  EXPECT_EQ(dead.reason.rfind("deadlock", 0), 0u) << dead.reason;
  EXPECT_NE(dead.reason.find("'LEFT'"), std::string::npos) << dead.reason;
  EXPECT_NE(dead.reason.find("'RIGHT'"), std::string::npos) << dead.reason;
  // The partner reads the deadlock answer as blocked by LEFT too: no third state, no loop.
  EXPECT_EQ(blocker_prefix(deadlock_reason("RIGHT", "left", "LEFT", "x")), "LEFT");
}

TEST(BlockerPrefix, OnlyFromTheRulesReasons) {
  EXPECT_EQ(blocker_prefix(""), "");
  EXPECT_EQ(blocker_prefix("infeasible: neighbour 'a' link 'l' at t = 1 s"), "");
  EXPECT_EQ(blocker_prefix("blocked by neighbour 'a' [A"), "");
  EXPECT_EQ(blocker_prefix("x; " + blocked_reason("n", "N2", Treatment::kHeldAtState, 0, "y")),
            "N2");
}

}  // namespace
}  // namespace kinograph::fleet

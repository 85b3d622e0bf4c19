// The coordination rule: a strict priority order (goal time, then name); every neighbour's plan
// in force followed, silent and planless neighbours held; a replan only for the own goal or a
// higher-priority neighbour's change, once per change; and a fleet that settles within N − 1
// rounds after every robot gets a new goal (random goal times and plan churn, seeded); a goal
// refused after or before a higher plan came; a blocked goal tried again once per new plan of its
// blocker, whatever its priority, at most kMaxBlockedRetries times, and a fleet with refusals and
// retries that still falls quiet.
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

TEST(Coordinate, FollowsEveryPlanInForceAndHoldsTheOthers) {
  const PriorityKey own{200, "mid"};
  const std::vector<NeighbourView> n = {{"first", {100, "first"}, 7, false},
                                        {"last", {300, "last"}, 9, false},
                                        {"quiet", {150, "quiet"}, 4, true},
                                        {"planless", {120, "planless"}, std::nullopt, false}};
  const Decision d = coordinate(own, n, {}, true);
  EXPECT_TRUE(d.replan);
  EXPECT_EQ(d.treatment,
            (std::vector<Treatment>{Treatment::kAlongPlan, Treatment::kAlongPlan,
                                    Treatment::kHeldAtState, Treatment::kHeldAtState}));
  EXPECT_EQ(d.around.at("first"), 7);
  EXPECT_EQ(d.around.at("last"), 9);  // lower, but under way: followed, never a trigger
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

TEST(Coordinate, ReplansAfterARefusalWhenAHigherNeighboursPlanArrives) {
  const PriorityKey own{200, "mid"};
  // Tried while the other had no goal (lowest, held at its state), and refused.
  std::vector<NeighbourView> n = {{"high", {}, std::nullopt, false}};
  const PlannedAround tried = coordinate(own, n, {}, true).around;
  n[0] = {"high", {100, "high"}, 3, false};  // then its earlier goal's plan came
  const Decision d = coordinate(own, n, tried, false);
  EXPECT_TRUE(d.replan) << d.reason;
  EXPECT_FALSE(d.retry);
  EXPECT_EQ(d.treatment, std::vector<Treatment>{Treatment::kAlongPlan});
}

TEST(Coordinate, RetriesABlockedGoalOncePerNewPlanOfTheBlockerWhateverItsPriority) {
  const PriorityKey own{100, "high"};
  std::vector<NeighbourView> n = {{"low", {300, "low"}, std::nullopt, false},
                                  {"other", {400, "other"}, 2, false}};
  const PlannedAround tried = coordinate(own, n, {}, true).around;
  BlockedGoal blocked{"low", std::nullopt, 0};
  EXPECT_FALSE(coordinate(own, n, tried, false, &blocked).replan);  // the blocker did not move

  n[1].plan_id = 3;  // another lower neighbour moved: not the blocker
  EXPECT_FALSE(coordinate(own, n, tried, false, &blocked).replan);

  n[0].plan_id = 5;  // the blocker planned: one retry, following it along its plan
  const Decision d = coordinate(own, n, tried, false, &blocked);
  EXPECT_TRUE(d.replan);
  EXPECT_TRUE(d.retry);
  EXPECT_EQ(d.treatment, (std::vector<Treatment>{Treatment::kAlongPlan, Treatment::kAlongPlan}));
  EXPECT_EQ(d.around.at("low"), 5);
  EXPECT_EQ(d.plans, (std::vector<std::optional<std::int64_t>>{5, 3}));
  EXPECT_NE(d.reason.find("neighbour 'low', which blocked the goal, has plan 5"), std::string::npos)
      << d.reason;

  blocked = {"low", 5, 1};  // refused again around plan 5: only its next plan is a retry
  EXPECT_FALSE(coordinate(own, n, d.around, false, &blocked).replan);
  n[0].plan_id = 6;
  EXPECT_TRUE(coordinate(own, n, d.around, false, &blocked).retry);

  blocked.retries = kMaxBlockedRetries;  // the bound per goal
  EXPECT_FALSE(coordinate(own, n, d.around, false, &blocked).replan);
  blocked.retries = 1;
  n[0].silent = true;  // a silent blocker is held at its last state: nothing new to follow
  EXPECT_FALSE(coordinate(own, n, d.around, false, &blocked).replan);
  n[0].silent = false;
  const Decision goal = coordinate(own, n, d.around, true, &blocked);  // a new goal: no retry
  EXPECT_FALSE(goal.retry);
  EXPECT_TRUE(goal.replan);
}

TEST(Coordinate, AHigherBlockersNewPlanIsTheRulesReplanNotARetry) {
  const PriorityKey own{200, "mid"};
  std::vector<NeighbourView> n = {{"high", {100, "high"}, 7, false}};
  const PlannedAround tried = coordinate(own, n, {}, true).around;
  const BlockedGoal blocked{"high", 7, 0};
  n[0].plan_id = 8;
  const Decision d = coordinate(own, n, tried, false, &blocked);
  EXPECT_TRUE(d.replan);
  EXPECT_FALSE(d.retry);
}

// The rounds above with refusals: a replan is refused, blocked by a random neighbour, with
// probability 1/2, and retried under the rule. Each robot retries a goal at most
// kMaxBlockedRetries times, and the fleet still falls quiet: a robot's plans are bounded by the
// plans of those above it plus its retries.
TEST(Coordinate, FleetWithRefusalsAndRetriesFallsQuiet) {
  std::mt19937 rng(2027);
  for (int trial = 0; trial < 200; ++trial) {
    const int N = 2 + trial % 7;
    std::uniform_int_distribution<int> goal_time(0, 3), other(0, N - 2);
    std::bernoulli_distribution refused(0.5);
    std::vector<PriorityKey> keys(N);
    for (int i = 0; i < N; ++i) keys[i] = {goal_time(rng), "robot" + std::to_string(i)};
    std::vector<std::optional<std::int64_t>> plan(N);
    std::vector<PlannedAround> planned(N);
    std::vector<std::optional<BlockedGoal>> blocked(N);
    std::vector<int> retries(N, 0);
    std::int64_t next_id = 0;
    std::vector<bool> goal_changed(N, true);
    const int rounds = 4 * N * (kMaxBlockedRetries + 2);
    int last_active = -1;
    for (int round = 0; round < rounds; ++round) {
      std::vector<std::optional<std::int64_t>> published = plan;
      bool any = false;
      for (int i = 0; i < N; ++i) {
        std::vector<NeighbourView> views;
        for (int j = 0; j < N; ++j) {
          if (j != i) views.push_back({keys[j].robot, keys[j], plan[j], false});
        }
        if (blocked[i]) blocked[i]->retries = retries[i];
        const Decision d = coordinate(keys[i], views, planned[i], goal_changed[i],
                                      blocked[i] ? &*blocked[i] : nullptr);
        if (!d.replan) continue;
        any = true;
        planned[i] = d.around;
        if (d.retry) ++retries[i];
        blocked[i].reset();
        if (refused(rng)) {
          const int k = other(rng);
          blocked[i] = BlockedGoal{views[k].name, d.plans[k], retries[i]};
        } else {
          published[i] = ++next_id;
        }
      }
      std::fill(goal_changed.begin(), goal_changed.end(), false);
      plan = published;
      if (any) last_active = round;
    }
    EXPECT_LT(last_active, rounds - N) << "trial " << trial << " with " << N << " robots";
    for (int i = 0; i < N; ++i) EXPECT_LE(retries[i], kMaxBlockedRetries);
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
  const Blocker a{"a", "A", Treatment::kAlongPlan, 2.5, false, {}};
  const Remedy r = remedy("B", a, 0.0, 1.0, "", "overlap");
  EXPECT_EQ(r.kind, Remedy::Kind::kWait);
  EXPECT_DOUBLE_EQ(r.wait.wait, 2.5);
  EXPECT_DOUBLE_EQ(r.wait.horizon, 3.5);
  EXPECT_NE(r.reason.find("neighbour 'a'"), std::string::npos) << r.reason;
}

TEST(Remedy, FailsWhenStillBlockedAfterWaitingOrWhenWaitingIsOff) {
  const Blocker a{"a", "A", Treatment::kAlongPlan, 2.5, false, {}};
  const Remedy after = remedy("B", a, 2.5, 1.0, "", "overlap at the goal");
  EXPECT_EQ(after.kind, Remedy::Kind::kFail);
  EXPECT_NE(after.reason.find("even after waiting 2.500 s"), std::string::npos) << after.reason;
  EXPECT_EQ(blocker_prefix(after.reason), "A");
  const Remedy off = remedy("B", a, 0.0, 1.0, "waiting is off", "overlap");
  EXPECT_EQ(off.kind, Remedy::Kind::kFail);
  EXPECT_NE(off.reason.find("waiting is off"), std::string::npos) << off.reason;
}

TEST(Remedy, WaitsForAHeldNeighbourUnderWayThenFailsOrFindsTheDeadlock) {
  Blocker b{"right", "RIGHT", Treatment::kHeldAtState, 1.5, false, {}, /*moving=*/true};
  const Remedy r = remedy("LEFT", b, 0.0, 3.0, "", "overlap");
  ASSERT_EQ(r.kind, Remedy::Kind::kWait);
  EXPECT_DOUBLE_EQ(r.wait.wait, 1.5);
  EXPECT_DOUBLE_EQ(r.wait.horizon, 4.5);
  EXPECT_EQ(remedy("LEFT", b, 0.0, 3.0, "waiting is off", "overlap").kind, Remedy::Kind::kFail);
  const Remedy after = remedy("LEFT", b, 1.5, 3.0, "", "overlap");
  EXPECT_EQ(after.kind, Remedy::Kind::kFail);
  EXPECT_EQ(blocker_prefix(after.reason), "RIGHT");
  b.blocked_by_own = true;  // standing where its plan ended, it waits for this robot
  EXPECT_EQ(remedy("LEFT", b, 1.5, 3.0, "", "overlap").kind, Remedy::Kind::kDeadlock);
}

TEST(Remedy, AHeldNeighbourBlockedByThisRobotIsADeadlockNamingBoth) {
  Blocker b{"right", "RIGHT", Treatment::kHeldAtState, 0.0, false, {}};
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

TEST(Remedy, ACycleOfBlockedRobotsIsADeadlockNamingTheCycle) {
  Blocker b{"b", "B", Treatment::kHeldAtState, 0.0, true, {"B", "C"}};  // B by C, C by A
  const Remedy dead = remedy("A", b, 0.0, 3.0, "", "goal overlaps it");
  EXPECT_EQ(dead.kind, Remedy::Kind::kDeadlock);
  EXPECT_NE(dead.reason.find("robots 'A' -> 'B' -> 'C' -> 'A' each stand where the next must go"),
            std::string::npos)
      << dead.reason;
  EXPECT_EQ(blocker_prefix(dead.reason), "B");
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

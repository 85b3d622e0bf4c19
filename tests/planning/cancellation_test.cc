// Cooperative cancellation outside the solvers: with this thread's flag set, the walks a plan
// makes before its first solve (the detour ranking, the path search) and after it (the
// validator's collision walk) stop with graph::Cancelled; with the flag clear they finish.
// These are what kept a cancelled plan of the 400-step iiwa desk task running for up to 100 ms.
#include <gtest/gtest.h>

#include <atomic>
#include <string>

#include "kinograph/graph/cancellation.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/batch/path_search.h"
#include "kinograph/planning/formulation/initialization.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/validate.h"

namespace kinograph::planning {
namespace {

// The straight line to the goal runs through the desk: every walk below has work to do.
Problem desk() {
  return load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml").problem;
}

TEST(PlanningCancellation, ASetFlagStopsTheWalksBeforeTheFirstSolve) {
  const Problem p = desk();
  std::atomic<bool> cancel{true};
  graph::CancellationScope scope(cancel);
  EXPECT_THROW(segment_clearance(p, p.start_q, p.goal.q, 32), graph::Cancelled);
  EXPECT_THROW(detour_candidates(p, p.goal.q), graph::Cancelled);
  EXPECT_THROW(search_path(p, p.goal.q), graph::Cancelled);
}

TEST(PlanningCancellation, ASetFlagStopsTheValidatorsCollisionWalk) {
  const Problem p = desk();
  const Plan plan = BatchPlanner().plan(p);
  ASSERT_GE(plan.q.rows(), 2);
  std::atomic<bool> cancel{true};
  graph::CancellationScope scope(cancel);
  EXPECT_THROW(validate(p, plan), graph::Cancelled);
}

TEST(PlanningCancellation, AClearFlagLetsTheWalksFinish) {
  const Problem p = desk();
  std::atomic<bool> cancel{false};
  graph::CancellationScope scope(cancel);
  EXPECT_LT(segment_clearance(p, p.start_q, p.goal.q, 32), 0.0);  // through the desk
  EXPECT_FALSE(detour_candidates(p, p.goal.q).empty());
  EXPECT_TRUE(search_path(p, p.goal.q).has_value());
}

}  // namespace
}  // namespace kinograph::planning

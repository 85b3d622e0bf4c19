// Constraint generation for the limits between the knots: which intervals intervals_near_limits
// flags, the graphs of IntervalRows, and the Acrobot's knot-only plan that needs them.
#include "kinograph/planning/batch/interval_limits.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "kinograph/planning/formulation/dfg_builder.h"
#include "kinograph/planning/formulation/planning_graph.h"
#include "kinograph/planning/solver/augmented_lagrangian.h"
#include "kinograph/planning/validate.h"
#include "test_problems.h"

namespace kinograph::planning {
namespace {

using testing::FastRr;

TEST(IntervalLimits, FlagsTheIntervalsNearALimitBetweenTheKnots) {
  // Joint 0 moves at 0, 0.2, 0.2, 0 rad/s at the knots and peaks at 0.3 rad/s between knots 1
  // and 2; the other intervals' interior points stay at or below 0.162 rad/s.
  FastRr f;
  f.problem.objectives.limit_epsilon = 0;
  f.limit_velocity(0.25);
  EXPECT_EQ(intervals_near_limits(f.problem, f.plan, 0.1), (std::vector<char>{0, 1, 0}));
  // Within 10 % of 0.17 rad/s: every interval; far from every limit: none.
  f.limit_velocity(0.17);
  EXPECT_EQ(intervals_near_limits(f.problem, f.plan, 0.1), (std::vector<char>{1, 1, 1}));
  f.limit_velocity(0.5);
  EXPECT_EQ(intervals_near_limits(f.problem, f.plan, 0.1), (std::vector<char>{0, 0, 0}));
  // The margin is a fraction of the limit: 0.162 is within 70 % of 0.5 rad/s, and joint 0's
  // torque in intervals 1 and 2 (at most 25.4 and 27.0 N·m) within 70 % of its 60 N·m.
  EXPECT_EQ(intervals_near_limits(f.problem, f.plan, 0.7), (std::vector<char>{1, 3, 3}));
  // The effort alone: within 10 % of 27.5 N·m, intervals 1 and 2 need their torque rows (those
  // that cost inverse dynamics at every point), none its q and q̇ rows.
  auto m = std::make_shared<dynamics::Model>(*f.problem.model);
  m->bodies[0].limits.effort = 27.5;
  f.problem.model = m;
  EXPECT_EQ(intervals_near_limits(f.problem, f.plan, 0.1),
            (std::vector<char>{0, kEffortLimitRows, kEffortLimitRows}));
  // No interior limit points, nothing to flag.
  f.limit_velocity(0.25);
  f.problem.objectives.limit_substeps = 0;
  EXPECT_EQ(intervals_near_limits(f.problem, f.plan, 0.1), (std::vector<char>{0, 0, 0}));
}

// The interval factors of a graph: (interval, rows) in graph order.
std::vector<std::pair<int, int>> interval_factors(const PlanningGraph& pg) {
  std::vector<std::pair<int, int>> out;
  for (const FactorEntry& e : pg.entries) {
    if (e.key.role == FactorRole::kInterval) out.push_back({e.key.step, e.factor->residual_dim()});
  }
  return out;
}

TEST(IntervalLimits, RowsOfTheGraph) {
  Problem p = testing::acrobot_swingup();
  p.steps = 4;
  const Trajectory init = straight_line(p, p.goal.q);
  const int n = p.model->nq();
  // Knot-only: no interval factor, and the collocation covers both joints (4 rows of each).
  IntervalRows knots;
  knots.knots_only = true;
  const PlanningGraph only = build_graph(p, init, {}, GraphForm::kBatch, knots);
  EXPECT_TRUE(interval_factors(only).empty());
  for (const FactorEntry& e : only.entries) {
    if (e.key.role == FactorRole::kCollocation) {
      EXPECT_EQ(e.factor->residual_dim(), 2 * n);
    }
  }
  // The shoulder's two defect rows everywhere; at each limit point of interval 2 the elbow's τ,
  // q, q̇ bounds and the shoulder's q, q̇ bounds (as far as finite), of interval 3 the elbow's τ
  // alone, of interval 1 the q and q̇ bounds alone.
  IntervalRows some;
  some.limits = {kNoLimitRows, kMotionLimitRows, kAllLimitRows, kEffortLimitRows};
  const auto rows = interval_factors(build_graph(p, init, {}, GraphForm::kBatch, some));
  const auto all = interval_factors(build_graph(p, init));
  ASSERT_EQ(rows.size(), 4u);
  ASSERT_EQ(all.size(), 4u);
  EXPECT_EQ(rows[0].second, 2);
  EXPECT_EQ(rows[2].second, all[2].second);
  EXPECT_EQ(rows[3].second, 2 + limit_points(p.objectives.limit_substeps, p.dt()));
  EXPECT_GT(rows[1].second, 2);
  EXPECT_EQ(rows[1].second + rows[3].second - 2, all[1].second);
  some.limits = {1};
  EXPECT_THROW(build_graph(p, init, {}, GraphForm::kBatch, some), std::invalid_argument);
}

TEST(IntervalLimits, AcrobotKnotOnlyPlanNeedsTheRowsThePlannerAdds) {
  // The knot-only solve of the swing-up is over the elbow's limit between some knots and its
  // shoulder misses the dynamics (what the batch planner's later rounds repair); few
  // intervals need limit points.
  const Problem p = testing::acrobot_swingup();
  IntervalRows knots;
  knots.knots_only = true;
  PlanningGraph pg = build_graph(p, straight_line(p, p.goal.q), {}, GraphForm::kBatch, knots);
  ConstraintState state;
  AugmentedLagrangian al(pg.constraints(false), state);
  const OuterLoopResult r = solve_outer_loop(pg.graph, pg.values, al, {}, p.name);
  ASSERT_EQ(r.status, PlanStatus::kConverged) << r.reason;
  const Plan plan = plan_from_values(p, pg.values);
  const Validation v = validate(p, plan);
  EXPECT_FALSE(v.valid);
  EXPECT_GT(v.max_tau_violation_between, 0.5);
  // The shoulder's dynamics from each knot do not arrive at the next one.
  EXPECT_GT(v.max_velocity_consistency, ValidationThresholds{}.velocity_consistency);
  const std::vector<char> near = intervals_near_limits(p, plan, 0.1);
  const long flagged = std::count_if(near.begin(), near.end(), [](char c) { return c != 0; });
  EXPECT_GT(flagged, 0);
  EXPECT_LT(flagged, p.steps);
  // The elbow's torque among them, where it is over its limit.
  EXPECT_TRUE(std::any_of(near.begin(), near.end(),
                          [](char c) { return (c & kEffortLimitRows) != 0; }));
}

}  // namespace
}  // namespace kinograph::planning

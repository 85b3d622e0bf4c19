// Self-collision and the floor: the hinge factor's Jacobians with both bodies moving, the
// planning graph's kSelfCollision entries in both forms, check_problem and validate naming the
// pair, and the planner keeping the robot's links apart and off the floor.
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "kinograph/collision/collision_world.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/graph/testing/numerical_jacobian.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/clearance_world.h"
#include "kinograph/planning/factors/collision_factors.h"
#include "kinograph/planning/factors/trajectory_factors.h"
#include "kinograph/planning/formulation/initialization.h"
#include "kinograph/planning/formulation/planning_graph.h"
#include "kinograph/planning/incremental/incremental_planner.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/problem_check.h"
#include "kinograph/planning/validate.h"
#include "measured_values.h"
#include "test_problems.h"

namespace kinograph::planning {
namespace {

using graph::testing::check_jacobians;
using testing::failures;
using testing::iiwa_with_block;
using testing::load_robot;

const std::string kScenes = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/";

Eigen::VectorXd q7(double a, double b, double c, double d, double e, double f, double g) {
  Eigen::VectorXd q(7);
  q << a, b, c, d, e, f, g;
  return q;
}

// A plan along the planner's smooth straight line (physics not exact: for collision checks).
Plan straight_plan(const Problem& problem) {
  return plan_from_trajectory(problem, straight_line(problem, problem.goal.q));
}

bool any_failure_has(const Validation& v, const std::string& text) {
  for (const std::string& f : v.failures) {
    if (f.find(text) != std::string::npos) return true;
  }
  return false;
}

TEST(SelfCollisionFactor, JacobiansWithBothBodiesMovingAndTheFloor) {
  auto model = iiwa_with_block();
  SelfPairs self{{{4, 6}}, 0.01};
  // A query distance of 2 m reports every pair, so every row has a gradient.
  auto ctx = std::make_shared<CollisionContext>(
      model, std::vector<collision::Obstacle>{floor_obstacle(0.0)}, 2.0, &self);
  ASSERT_GT(ctx->num_pairs, ctx->num_obstacle_rows);
  graph::Values v;
  v.insert(q_key(0), q7(0.3, 1.4, -0.5, -1.9, 0.6, -1.2, 0.2));
  v.insert(v_key(0), q7(0.2, -0.1, 0.3, 0.2, -0.4, 0.1, 0.3));
  v.insert(q_key(1), q7(0.4, 1.5, -0.4, -2.0, 0.5, -1.1, 0.1));
  v.insert(v_key(1), q7(-0.1, 0.2, 0.1, -0.3, 0.2, 0.3, -0.2));
  for (double s : {0.0, 0.4}) {
    CollisionFactor f(0, s, 0.2, 0.05, 0.01, ctx);
    const Eigen::VectorXd z = testing::measured_values(f, v);
    EXPECT_LT(z.head(ctx->num_obstacle_rows).maxCoeff(), 2.0);  // floor rows reported
    EXPECT_LT(z.tail(ctx->num_pairs - ctx->num_obstacle_rows).minCoeff(), 0.2);
    auto c = check_jacobians(f, v, {1e-4, 1e-3, false});
    EXPECT_TRUE(c.ok) << c.report();
  }
  // Self rows have the self ε, floor rows the obstacle ε.
  CollisionFactor f(0, 0.0, 0.2, 0.05, 0.01, ctx);
  EXPECT_EQ(f.rows()[0].lower, 0.05);
  EXPECT_EQ(f.rows()[ctx->num_pairs - 1].lower, 0.01);
}

TEST(SelfCollisionEntries, BothGraphFormsHoldThemAtEveryStateAndSubStep) {
  Problem p = testing::iiwa_swing(10);
  p.self_and_floor.floor = 0.0;
  p.objectives.collision_substeps = 2;
  for (GraphForm form : {GraphForm::kBatch, GraphForm::kIncremental}) {
    const PlanningGraph pg = build_graph(p, straight_line(p, p.goal.q), {}, form);
    int count = 0;
    for (const FactorEntry& e : pg.entries) {
      if (e.key.role != FactorRole::kSelfCollision) continue;
      ++count;
      EXPECT_EQ(e.key.index, -1);
      EXPECT_TRUE(e.key.depends_on_dt());
    }
    EXPECT_EQ(count, 10 + 10 * 2);  // states 1..N and 2 sub-steps in each of the N intervals
  }
  p.self_and_floor.self_collision = false;
  p.self_and_floor.floor.reset();
  EXPECT_TRUE(self_collision_entries(p, {}).empty());
}

TEST(MountingFloor, FloorMountedArmsOnlyAndTheBaseIsNotChecked) {
  EXPECT_EQ(mounting_floor(*load_robot("robots/iiwa14/iiwa14.urdf")), 0.0);
  EXPECT_FALSE(mounting_floor(*load_robot("robots/acrobot/acrobot.urdf")).has_value());
  EXPECT_FALSE(mounting_floor(*load_robot("robots/rr/rr.urdf")).has_value());
  // The iiwa's base stands on the floor, yet a resting arm is clear of it.
  Problem p = testing::iiwa_swing();
  p.self_and_floor.floor = 0.0;
  p.self_and_floor.allowed_pairs = {{4, 6}};
  EXPECT_EQ(check_problem(p), "");
}

// The case: from the desk scene's start, a goal that folds link 5 into the base and
// puts the flange under the floor. Refused before planning, never called valid.
TEST(Acceptance, SelfCollidingGoalUnderTheFloorIsRefused) {
  Scene scene = load_scene(kScenes + "iiwa_desk.yaml");
  Problem& p = scene.problem;
  ASSERT_EQ(p.self_and_floor.floor, 0.0);
  p.goal.q = q7(0, 2, 0, -2, 0, -2, 0);
  const Plan plan = BatchPlanner().plan(p);
  EXPECT_FALSE(plan.success()) << failures(plan);
  EXPECT_EQ(plan.stats.status, PlanStatus::kInvalidProblem) << failures(plan);
  EXPECT_NE(plan.stats.reason.find("goal configuration is in collision"), std::string::npos)
      << plan.stats.reason;
  // Without the floor the self-collision remains, named with its depth (2.1 cm).
  p.self_and_floor.floor.reset();
  const std::string why = check_problem(p);
  EXPECT_NE(why.find("links 'iiwa_link_0' and 'iiwa_link_5' overlap by 0.02"), std::string::npos)
      << why;
  // The validator rejects a plan that goes there, naming the pair and the time.
  p.self_and_floor.floor = 0.0;
  const Validation v = validate(p, straight_plan(p));
  EXPECT_FALSE(v.valid);
  EXPECT_LT(v.min_clearance, -0.1);  // the block is more than 10 cm into the floor
  EXPECT_TRUE(any_failure_has(v, "the floor overlap by")) << ::testing::PrintToString(v.failures);
  EXPECT_TRUE(any_failure_has(v, " s (required clearance 0 m)"))
      << ::testing::PrintToString(v.failures);
}

TEST(Validate, PlanThroughTheFloorIsInvalidAndTheFloorCanBeSwitchedOff) {
  Problem p;
  p.model = load_robot("robots/iiwa14/iiwa14.urdf");
  p.horizon = 2;
  p.steps = 20;
  p.start_q = q7(0, 1.2, 0, 0, 0, 0, 0);
  p.start_qd = Eigen::VectorXd::Zero(7);
  p.goal.q = q7(0, 2.0, 0, 0, 0, 0, 0);  // arm pointing 25° below horizontal: flange at z < 0
  p.self_and_floor.floor = 0.0;
  const Plan plan = straight_plan(p);
  const Validation with = validate(p, plan);
  EXPECT_FALSE(with.valid);
  EXPECT_LT(with.min_clearance, 0);
  EXPECT_TRUE(any_failure_has(with, "link 'iiwa_link_7' and the floor overlap by"))
      << ::testing::PrintToString(with.failures);
  p.self_and_floor.floor.reset();
  const Validation without = validate(p, plan);
  EXPECT_GE(without.min_clearance, 0);
  EXPECT_FALSE(any_failure_has(without, "collision")) << ::testing::PrintToString(without.failures);
  // A floor lower than the flange ever gets: clear.
  p.self_and_floor.floor = -0.2;
  EXPECT_GE(validate(p, plan).min_clearance, 0);
}

TEST(Validate, SelfCollisionBetweenTheKnotsIsFound) {
  // Links 5 and 7 overlap when |q6| > 1.83 rad. Both knots have q6 = 1.6, but their velocities
  // (within the 2.36 rad/s limit) and q̈6 = −4.6 rad/s² make the interpolant swing q6 to 2.18
  // at mid-interval.
  Problem p;
  p.model = load_robot("robots/iiwa14/iiwa14.urdf");
  p.horizon = 1;
  p.steps = 1;
  p.start_q = q7(0, 0.5, 0, -1, 0, 1.6, 0);
  p.start_qd = q7(0, 0, 0, 0, 0, 2.3, 0);
  p.goal.q = p.start_q;
  Plan plan;
  plan.q = Eigen::MatrixXd(2, 7);
  plan.q << p.start_q.transpose(), p.goal.q.transpose();
  plan.qd = Eigen::MatrixXd(2, 7);
  plan.qd << p.start_qd.transpose(), -p.start_qd.transpose();
  plan.qdd = Eigen::MatrixXd::Zero(2, 7);
  plan.qdd.col(5).setConstant(-2 * 2.3);
  plan.tau = Eigen::MatrixXd::Zero(2, 7);
  plan.t = {0, 1};
  EXPECT_EQ(check_problem(p), "");  // both knots are clear
  Validation v = validate(p, plan);
  EXPECT_TRUE(any_failure_has(v, "links 'iiwa_link_5' and 'iiwa_link_7' overlap by"))
      << ::testing::PrintToString(v.failures);
  EXPECT_TRUE(any_failure_has(v, "at t = 0.4") || any_failure_has(v, "at t = 0.5"))
      << ::testing::PrintToString(v.failures);
  // Allowed, the pair is not checked.
  p.self_and_floor.allowed_pairs = {{4, 6}};
  v = validate(p, plan);
  EXPECT_FALSE(any_failure_has(v, "collision")) << ::testing::PrintToString(v.failures);
  // Self-collision off: not checked either.
  p.self_and_floor.allowed_pairs = {};
  p.self_and_floor.self_collision = false;
  v = validate(p, plan);
  EXPECT_FALSE(any_failure_has(v, "collision")) << ::testing::PrintToString(v.failures);
}

TEST(Planner, GoesAroundTheFloorThatTheStraightLineCrosses) {
  // The arm reaches out low and sideways and swings its forearm (joint 4) from one side to the
  // other: half way the flange would be 8 cm into the floor.
  Problem p;
  p.model = load_robot("robots/iiwa14/iiwa14.urdf");
  p.horizon = 3;
  p.steps = 30;
  p.start_q = q7(0, 2.0, M_PI / 2, -1.2, 0, 0, 0);
  p.start_qd = Eigen::VectorXd::Zero(7);
  p.goal.q = q7(0, 2.0, M_PI / 2, 1.2, 0, 0, 0);
  p.self_and_floor.allowed_pairs = {{4, 6}};
  p.self_and_floor.floor = 0.0;
  ASSERT_EQ(check_problem(p), "");
  EXPECT_LT(validate(p, straight_plan(p)).min_clearance, -0.05);
  const Plan plan = BatchPlanner().plan(p);
  EXPECT_TRUE(plan.success()) << failures(plan);
  EXPECT_GE(plan.validation.min_clearance, 0);
  // Planned without the floor, the same move goes through it.
  Problem blind = p;
  blind.self_and_floor.floor.reset();
  const Plan through = BatchPlanner().plan(blind);
  EXPECT_LT(validate(p, through).min_clearance, 0);
}

TEST(SelfCollisionEntries, SelfAndFloorRowsTakeTheSelfEpsilon) {
  Problem p = testing::iiwa_swing(4);
  p.self_and_floor.floor = 0.0;
  p.objectives.collision_epsilon = 0.07;
  p.objectives.self_collision_epsilon = 0.03;
  const std::vector<FactorEntry> entries = self_collision_entries(p, {});
  ASSERT_FALSE(entries.empty());
  const std::vector<RowSpec>& rows = entries[0].constrained->rows();
  EXPECT_GT(rows.size(), 19u + 50u);  // 19 floor rows (the arm's moving geometries and the block)
  for (const RowSpec& r : rows) EXPECT_EQ(r.lower, 0.03);
}

TEST(IncrementalPlanner, ObstacleChangesKeepTheSelfFactorsAndANewHorizonRebuildsThem) {
  Problem p = testing::iiwa_swing(10);
  p.self_and_floor.floor = 0.0;
  p.self_and_floor.allowed_pairs = {{4, 6}};
  IncrementalPlanner planner;
  const Plan first = planner.plan(p);
  ASSERT_TRUE(first.success()) << failures(first);
  // An obstacle far away: only its own hinges are added, nothing is replaced.
  collision::Obstacle ball;
  ball.id = 3;
  ball.shape = collision::Shape::sphere(0.05);
  ball.pose.translation() = Eigen::Vector3d(-1.5, 0, 1.5);
  const Plan with_ball = planner.add_or_move_obstacle(ball);
  EXPECT_TRUE(with_ball.success()) << failures(with_ball);
  EXPECT_EQ(planner.last_stats().factors_replaced, 0);
  EXPECT_EQ(planner.last_stats().factors_added, 20);  // states 1..10 and one sub-step each
  // A new horizon replaces every Δt-dependent factor: GP prior and collocation (2 × 10), the
  // dynamics between the knots (one per interval in the new graph; the batch plan it started
  // from had them only on the intervals it generated them for, up to 10), the ball's hinges
  // (20) and the self/floor hinges (20), each rebuilt.
  const Plan longer = planner.set_horizon(2.4);
  EXPECT_TRUE(longer.success()) << failures(longer);
  EXPECT_GE(planner.last_stats().factors_replaced, 60);
  EXPECT_LE(planner.last_stats().factors_replaced, 70);
  EXPECT_EQ(planner.last_stats().factors_added, 70);
}

TEST(CheckProblem, AllowedPairsAndTheSwitchDecideWhatIsInCollision) {
  Problem p = testing::iiwa_swing();
  p.start_q = q7(-0.9, 0.7, 0, -1.2, 0, 2.0, 0);  // flange inside link 5's capsule
  EXPECT_NE(check_problem(p).find("start configuration is in collision: links"), std::string::npos)
      << check_problem(p);
  p.self_and_floor.allowed_pairs = {{6, 4}};  // either order
  EXPECT_EQ(check_problem(p), "");
  p.self_and_floor.allowed_pairs = {};
  p.self_and_floor.self_collision = false;
  EXPECT_EQ(check_problem(p), "");
}

}  // namespace
}  // namespace kinograph::planning

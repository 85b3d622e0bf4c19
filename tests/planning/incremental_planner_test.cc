// iDFGP: incremental replans validate and agree with batch solves of the changed
// problem; obstacle moves, removals and start updates behave as the problem says.
#include "kinograph/planning/incremental/incremental_planner.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "kinograph/collision/collision_world.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/io/replan_change.h"
#include "kinograph/planning/factors/state_target_factor.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/replanner.h"
#include "kinograph/planning/factors/trajectory_factors.h"

#include "bench/common/iiwa_goals.h"
#include "kinograph/planning/goal_sampler.h"
#include "kinograph/planning/problem_check.h"
#include "tests/planning/test_problems.h"

namespace kinograph::planning {
namespace {

using testing::failures;

const std::string kScenes = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/";

Problem rr_problem() { return load_scene(kScenes + "rr_reach.yaml").problem; }

// Smallest clearance of the robot to the problem's obstacles over a plan, sampled densely.
double plan_clearance(const Problem& problem, const Plan& plan) {
  collision::CollisionWorld world(*problem.model);
  for (const auto& o : problem.obstacles) world.add_obstacle(o);
  dynamics::Data data(*problem.model);
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k + 1 < plan.q.rows(); ++k) {
    for (int i = 0; i < 10; ++i) {
      const double s = i / 10.0;
      const Eigen::VectorXd q =
          (1 - s) * plan.q.row(k).transpose() + s * plan.q.row(k + 1).transpose();
      dynamics::forward_kinematics(*problem.model, data, q);
      best = std::min(best, world.closest(data, 0).distance);
    }
  }
  return best;
}

TEST(StateTargetFactor, JacobianAndRows) {
  const StateTargetFactor f({q_key(0), v_key(0)}, 2, Eigen::Vector4d(1, 2, 3, 4), 1e-2);
  EXPECT_EQ(f.residual_dim(), 4);
  EXPECT_TRUE(f.target().isApprox(Eigen::Vector4d(1, 2, 3, 4)));
  graph::Values v;
  v.insert(q_key(0), Eigen::Vector2d(1.5, 2));
  v.insert(v_key(0), Eigen::Vector2d(3, 3));
  EXPECT_NEAR(f.violation(v), 1.0, 1e-12);
  EXPECT_NEAR(f.scaled_violation(v), 100.0, 1e-9);
  EXPECT_THROW(StateTargetFactor({q_key(0)}, 2, Eigen::Vector3d(1, 2, 3), 1.0),
               std::invalid_argument);
  EXPECT_THROW(StateTargetFactor({q_key(0)}, 2, Eigen::Vector2d(1, 2), 0.0), std::invalid_argument);
}

// The incremental graph (start and goal as constraints, per-obstacle collision factors) gives
// the batch planner's plan from the same initialization, and an empty change keeps it.
TEST(IncrementalPlanner, InitialPlanMatchesBatchPlanner) {
  const Problem p = rr_problem();
  const Plan reference = BatchPlanner().plan(p);
  ASSERT_TRUE(reference.success()) << failures(reference);
  IncrementalPlanner planner;
  const Plan a = planner.plan(p, &reference);
  ASSERT_TRUE(a.success()) << failures(a);
  const Plan b = BatchPlanner().plan(p, &reference);
  ASSERT_TRUE(b.success()) << failures(b);
  EXPECT_NEAR(a.stats.cost, b.stats.cost, 0.01 * b.stats.cost);
  EXPECT_LT((a.q - b.q).cwiseAbs().maxCoeff(), 2e-2);
  const Plan same = planner.replan(ProblemChange());
  ASSERT_TRUE(same.success()) << failures(same);
  EXPECT_EQ(same.stats.method, "incremental");
  // Settling in the Bayes tree (moderate μ, tighter final tolerance) may trade the last 1e-4 of
  // constraint slack for cost: within 2 %.
  EXPECT_NEAR(same.stats.cost, b.stats.cost, 0.02 * b.stats.cost);
}

// A goal change without obstacles: the incremental plan is the batch plan of the new problem
// (straight-line and warm-started batch solves agree there).
TEST(IncrementalPlanner, GoalChangeMatchesBatchSolve) {
  Problem p = rr_problem();
  p.obstacles.clear();
  IncrementalPlanner planner;
  ASSERT_TRUE(planner.plan(p).success());
  Goal g;
  g.q = Eigen::Vector2d(0.8, 1.0);
  const Plan inc = planner.set_goal(g);
  EXPECT_EQ(planner.last_stats().method, "incremental") << failures(inc);
  EXPECT_EQ(planner.last_stats().method, "incremental");
  EXPECT_EQ(inc.stats.method, "incremental");
  ASSERT_TRUE(inc.success()) << failures(inc);
  EXPECT_LT(inc.validation.goal_error, 1e-3);
  p.goal = g;
  const Plan batch = BatchPlanner().plan(p);
  ASSERT_TRUE(batch.success()) << failures(batch);
  EXPECT_NEAR(inc.stats.cost, batch.stats.cost, 0.01 * batch.stats.cost);
  EXPECT_LT((inc.q - batch.q).cwiseAbs().maxCoeff(), 1e-2);
}

// With the ball, a goal change keeps the plan's way around it: the incremental plan matches the
// batch solve warm-started from the previous plan (to 1e-2 rad; the batch solve, run to its own
// tolerance, may end a little lower).
TEST(IncrementalPlanner, GoalChangeAroundObstacleMatchesWarmBatch) {
  Problem p = rr_problem();
  IncrementalPlanner planner;
  const Plan first = planner.plan(p);
  ASSERT_TRUE(first.success()) << failures(first);
  Goal g;
  g.q = Eigen::Vector2d(1.0, 0.9);
  const Plan inc = planner.set_goal(g);
  EXPECT_EQ(planner.last_stats().method, "incremental");
  ASSERT_TRUE(inc.success()) << failures(inc);
  p.goal = g;
  const Plan batch = BatchPlanner().plan(p, &first);
  ASSERT_TRUE(batch.success()) << failures(batch);
  EXPECT_NEAR(inc.stats.cost, batch.stats.cost, 0.03 * batch.stats.cost);
  EXPECT_LT((inc.q - batch.q).cwiseAbs().maxCoeff(), 1e-2);
}

// Preparing the tree while idle changes no plan: the goal change and the start update after it
// answer the plans of an unprepared planner, each re-eliminating only the root of the tree.
TEST(IncrementalPlanner, APreparedTreeAnswersTheSameReplansReeliminatingOnlyTheRoot) {
  const Problem p = rr_problem();
  IncrementalPlanner prepared, plain;
  ASSERT_TRUE(prepared.plan(p).success());
  ASSERT_TRUE(plain.plan(p).success());
  const Plan before = prepared.current_plan();
  EXPECT_GT(prepared.prepare(), 0.0);
  EXPECT_EQ(prepared.current_plan().q, before.q);
  Goal g;
  g.q = Eigen::Vector2d(1.0, 0.9);
  const Plan a = prepared.set_goal(g);
  const Plan b = plain.set_goal(g);
  ASSERT_TRUE(a.success()) << failures(a);
  ASSERT_TRUE(b.success()) << failures(b);
  EXPECT_EQ(prepared.last_stats().updates, plain.last_stats().updates);
  EXPECT_LT(prepared.last_stats().variables_reeliminated,
            plain.last_stats().variables_reeliminated);
  EXPECT_LT(prepared.last_stats().full_reeliminations, plain.last_stats().full_reeliminations);
  EXPECT_LT((a.q - b.q).cwiseAbs().maxCoeff(), 1e-6);

  prepared.prepare();
  const Eigen::Vector2d q0 = p.start_q + Eigen::Vector2d(0.02, -0.01);
  const Plan c = prepared.update_start(q0, Eigen::Vector2d::Zero());
  const Plan d = plain.update_start(q0, Eigen::Vector2d::Zero());
  ASSERT_TRUE(c.success()) << failures(c);
  ASSERT_TRUE(d.success()) << failures(d);
  EXPECT_LT(prepared.last_stats().variables_reeliminated,
            plain.last_stats().variables_reeliminated);
  EXPECT_LT((c.q - d.q).cwiseAbs().maxCoeff(), 1e-6);
}

// The ball moved onto the current path: the replan goes around it.
TEST(IncrementalPlanner, ObstacleMovedIntoPathIsAvoided) {
  const Problem p = rr_problem();
  IncrementalPlanner planner;
  const Plan first = planner.plan(p);
  ASSERT_TRUE(first.success()) << failures(first);
  // Slide the ball from its place toward the arm's tip at mid-course until the current plan
  // runs into it (clearance below −3 cm).
  dynamics::Data data(*p.model);
  dynamics::forward_kinematics(*p.model, data, first.q.row(p.steps / 2).transpose());
  const Eigen::Vector3d tip =
      dynamics::frame_pose(*p.model, data, p.model->frame_index("ee")).translation();
  collision::Obstacle moved = p.obstacles.front();
  const Eigen::Vector3d from = moved.pose.translation();
  Problem changed = p;
  bool found = false;
  for (double s = 0.05; s <= 1.0 && !found; s += 0.05) {
    moved.pose.translation() = from + s * (tip - from);
    changed.obstacles.front() = moved;
    found = plan_clearance(changed, first) < -0.03 && check_problem(changed).empty();
  }
  ASSERT_TRUE(found) << "no ball position on the path";
  const Plan re = planner.move_obstacle(moved.id, moved.pose);
  ASSERT_TRUE(re.success()) << failures(re);
  EXPECT_GE(plan_clearance(changed, re), 0.0);
  EXPECT_GE(re.validation.min_clearance, 0.0);
  EXPECT_EQ(planner.last_stats().method, "incremental");
  EXPECT_TRUE(planner.problem().obstacles.front().pose.isApprox(moved.pose));
}

// Removing an obstacle and adding it back returns the original plan. The obstacle is a small
// sphere just inside the safety distance ε of the plan (an active constraint that bends the path
// a little), so the plan with it is a unique nearby optimum.
TEST(IncrementalPlanner, RemoveAndAddBackReturnsOriginalPlan) {
  const Problem p = rr_problem();
  // Converged replans: stopping at the first valid plan makes the result depend on the path
  // of changes (the plan around the pebble stays valid once the pebble is gone).
  IncrementalPlannerOptions options;
  options.stop_at_first_valid = false;
  IncrementalPlanner planner(options);
  const Plan first = planner.plan(p);
  ASSERT_TRUE(first.success()) << failures(first);
  dynamics::Data data(*p.model);
  dynamics::forward_kinematics(*p.model, data, first.q.row(p.steps / 3).transpose());
  const Eigen::Vector3d tip =
      dynamics::frame_pose(*p.model, data, p.model->frame_index("ee")).translation();
  collision::Obstacle pebble;
  pebble.id = 7;
  pebble.shape = collision::Shape::sphere(0.05);
  Problem only = p;
  bool found = false;
  for (double d = 0.6; d > 0 && !found; d -= 0.005) {
    pebble.pose.translation() = tip + Eigen::Vector3d(0, 0, d);
    only.obstacles = {pebble};
    found = plan_clearance(only, first) < 0.02;
  }
  ASSERT_TRUE(found);
  const Plan original = planner.add_or_move_obstacle(pebble);
  ASSERT_TRUE(original.success()) << failures(original);
  ASSERT_EQ(planner.problem().obstacles.size(), 2u);
  const Plan without = planner.remove_obstacle(pebble.id);
  ASSERT_TRUE(without.success()) << failures(without);
  ASSERT_EQ(planner.problem().obstacles.size(), 1u);
  EXPECT_GT((without.q - original.q).cwiseAbs().maxCoeff(), 1e-3) << "the pebble must matter";
  const Plan back = planner.add_or_move_obstacle(pebble);
  ASSERT_TRUE(back.success()) << failures(back);
  EXPECT_EQ(planner.last_stats().method, "incremental");
  EXPECT_NEAR(back.stats.cost, original.stats.cost, 0.01 * original.stats.cost);
  EXPECT_LT((back.q - original.q).cwiseAbs().maxCoeff(), 1e-2);
}

// A measured state off the plan becomes the new first step.
TEST(IncrementalPlanner, StartUpdateReanchorsPlan) {
  const Problem p = rr_problem();
  IncrementalPlanner planner;
  ASSERT_TRUE(planner.plan(p).success());
  const Eigen::Vector2d q0 = p.start_q + Eigen::Vector2d(0.05, -0.03);
  const Eigen::Vector2d v0(0.1, 0.05);
  const Plan re = planner.update_start(q0, v0);
  ASSERT_TRUE(re.success()) << failures(re);
  EXPECT_LT((re.q.row(0).transpose() - q0).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT((re.qd.row(0).transpose() - v0).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT(re.validation.goal_error, 1e-3);
}

// A longer horizon: the Δt-dependent factors are replaced and the plan still validates.
TEST(IncrementalPlanner, HorizonChange) {
  const Problem p = rr_problem();
  IncrementalPlanner planner;
  ASSERT_TRUE(planner.plan(p).success());
  const Plan re = planner.set_horizon(p.horizon * 1.2);
  ASSERT_TRUE(re.success()) << failures(re);
  EXPECT_NEAR(re.t.back(), p.horizon * 1.2, 1e-12);
}

// The problem `p` with its start `m` knots into `plan` (the robot went on along it).
Problem started_at(const Problem& p, const Plan& plan, int m) {
  Problem next = p;
  next.start_q = plan.q.row(m).transpose();
  next.start_qd = plan.qd.row(m).transpose();
  return next;
}

// A sphere sweeping past the arm's reach along a trajectory on the plan's clock (t from 0).
collision::Obstacle passing_ball(int id, double y) {
  collision::Obstacle o;
  o.id = id;
  o.shape = collision::Shape::sphere(0.1);
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity(), b = a;
  a.translation() = Eigen::Vector3d(-1.5, y, 2.6);
  b.translation() = Eigen::Vector3d(1.5, y, 2.6);
  o.pose = a;
  o.trajectory = collision::PoseTrajectory({0.0, 3.0}, {a, b});
  return o;
}

// The motion gone on along a plan: its knots from m on, then at rest where it ends.
TEST(GoneOn, KnotsFromMOnThenAtRestAtTheEnd) {
  const Problem p = rr_problem();
  const Plan first = BatchPlanner().plan(p);
  ASSERT_TRUE(first.success()) << failures(first);
  const int m = 3, N = p.steps;
  const Plan on = gone_on(first, m);
  EXPECT_EQ(on.t, first.t);
  EXPECT_EQ(on.q.row(0), first.q.row(m));
  EXPECT_EQ(on.qd.row(N - m), first.qd.row(N));
  for (int k = N - m + 1; k <= N; ++k) {
    EXPECT_EQ(on.q.row(k), first.q.row(N));
    EXPECT_TRUE(on.qd.row(k).isZero() && on.qdd.row(k).isZero());
  }
  EXPECT_THROW(gone_on(first, N + 1), std::invalid_argument);
  EXPECT_THROW(gone_on(first, -1), std::invalid_argument);
}

// A replan that goes on from a knot of the plan renames the tree's states instead of rebuilding
// it (keeping the factors it can), and the plan is the shifted problem's own (a converged shift and a
// batch solve of the shifted problem warm-started from the motion gone on agree).
TEST(IncrementalPlanner, ShiftGoesOnFromAKnotOfThePlan) {
  Problem p = rr_problem();
  p.obstacles.push_back(passing_ball(9, 0.6));
  IncrementalPlannerOptions options;
  options.stop_at_first_valid = false;
  IncrementalPlanner planner(options);
  const Plan first = planner.plan(p);
  ASSERT_TRUE(first.success()) << failures(first);
  const int m = 4;
  Problem next = started_at(p, first, m);
  next.obstacles.back() = passing_ball(10, 0.5);  // a neighbour's new plan: a new id
  ASSERT_EQ(planner.shift_refusal(next, m), "");
  const Plan re = planner.shift(next, m);
  ASSERT_TRUE(re.success()) << failures(re);
  EXPECT_EQ(planner.last_stats().method, "incremental");
  EXPECT_GT(planner.last_stats().factors_replaced, 0);
  EXPECT_LT((re.q.row(0) - first.q.row(m)).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_EQ(planner.problem().obstacles.back().id, 10);
  // The motion goes on smoothly from where it was.
  EXPECT_LT((re.q.topRows(2) - first.q.middleRows(m, 2)).cwiseAbs().maxCoeff(), 0.05);
  const Plan warm = gone_on(first, m);
  const Plan batch = BatchPlanner(options.batch).plan(next, &warm);
  ASSERT_TRUE(batch.success()) << failures(batch);
  EXPECT_NEAR(re.stats.cost, batch.stats.cost, 0.02 * batch.stats.cost + 1e-6);
  EXPECT_LT((re.q - batch.q).cwiseAbs().maxCoeff(), 2e-2);
}

// Shifting again and again (the states left behind pile up until the tree is rebuilt without
// them) keeps every plan valid and on the robot's way to the goal.
TEST(IncrementalPlanner, RepeatedShiftsStayValid) {
  Problem p = rr_problem();
  p.obstacles.push_back(passing_ball(100, 0.6));
  IncrementalPlanner planner;
  Plan plan = planner.plan(p);
  ASSERT_TRUE(plan.success()) << failures(plan);
  Problem next = p;
  for (int i = 1; i <= 20; ++i) {
    next = started_at(next, plan, 2);
    next.obstacles.back() = passing_ball(100 + i, 0.6 - 0.01 * i);
    plan = planner.shift(next, 2);
    ASSERT_TRUE(plan.success()) << "shift " << i << ": " << failures(plan);
    EXPECT_LT(plan.validation.goal_error, 1e-3);
  }
}

// A shift the problem does not allow is refused and leaves the planner as it was.
TEST(IncrementalPlanner, ShiftRefusals) {
  const Problem p = rr_problem();
  IncrementalPlanner planner;
  EXPECT_NE(planner.shift_refusal(p, 2), "");  // no plan yet
  const Plan first = planner.plan(p);
  ASSERT_TRUE(first.success());
  EXPECT_NE(planner.shift_refusal(started_at(p, first, 0), 0), "");
  EXPECT_NE(planner.shift_refusal(started_at(p, first, p.steps - 1), p.steps - 1), "");
  Problem elsewhere = started_at(p, first, 4);
  elsewhere.start_q(0) += 0.2;  // not where the plan has the robot at knot 4
  EXPECT_NE(planner.shift_refusal(elsewhere, 4), "");
  Problem other_goal = started_at(p, first, 3);
  other_goal.goal.q = Eigen::Vector2d(1.1, 0.7);
  EXPECT_NE(planner.shift_refusal(other_goal, 3), "");
  const Plan refused = planner.shift(other_goal, 3);
  EXPECT_EQ(refused.stats.status, PlanStatus::kInvalidProblem);
  EXPECT_EQ(planner.problem().start_q, p.start_q);
  EXPECT_TRUE(planner.shift(started_at(p, first, 3), 3).success());
}

// The Replanner shifts the tree when told that its warm start is the current plan gone on by
// some knots, and warm-starts anew when that is not so.
TEST(Replanner, MotionGoneOnAlongThePlanShiftsTheTree) {
  const Problem p = rr_problem();
  Replanner replanner;
  const Plan first = replanner.plan(p, true);
  ASSERT_TRUE(first.success()) << failures(first);
  const Plan warm = gone_on(first, 3);
  const Plan re = replanner.plan(started_at(p, first, 3), false, &warm, 3);
  ASSERT_TRUE(re.success()) << failures(re);
  EXPECT_EQ(replanner.last_report().method, "incremental");
  EXPECT_TRUE(replanner.last_report().incremental);
  const Plan on = gone_on(re, 5);
  Problem elsewhere = started_at(p, re, 5);
  elsewhere.start_qd(0) += 0.2;  // not how the plan has the robot move at knot 5
  const Plan other = replanner.plan(elsewhere, false, &on, 5);
  ASSERT_TRUE(other.success()) << failures(other);
  EXPECT_EQ(replanner.last_report().method, "warm-start");
}

// The iiwa desk task's goal 20 of the replanning benchmark with its desk top moved by seeded
// offsets: most moves replan incrementally, but some stall in the incremental replan while the
// batch planner's warm start detours widely around the desk; the fallback is that warm batch
// solve, carried into a new tree, and the next replan goes on from it. The moves are drawn in
// turn until one needs the fallback (today the first does; which one depends on rounding).
TEST(Replanner, AFailedReplanFallsBackToTheBatchPlannersWarmStart) {
  const Scene scene = load_scene(kScenes + "iiwa_desk.yaml");
  GoalSampler sampler(scene.problem, bench::iiwa_goal_options(1));
  const std::vector<Eigen::VectorXd> goals = sampler.sample(20);
  ASSERT_EQ(goals.size(), 20u);
  Problem first = scene.problem;
  first.goal.q = goals[19];

  ReplannerOptions options;
  options.retry_from_scratch = false;  // the warm batch solve alone must answer
  Replanner replanner(options);
  Plan previous = replanner.plan(first, true);
  ASSERT_TRUE(previous.success()) << failures(previous);
  std::mt19937_64 rng(5019);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  Problem moved = first;
  Plan re;
  bool fell_back = false;
  for (int draw = 0; draw < 25 && !fell_back; ++draw) {
    collision::Obstacle top = first.obstacles[0];
    do {
      top.pose = first.obstacles[0].pose;
      top.pose.translation() += Eigen::Vector3d(u(rng), u(rng), u(rng));
      moved.obstacles[0] = top;
    } while (!check_problem(moved).empty());
    ProblemChange change;
    change.add_or_move.push_back(top);
    re = replanner.replan(change);
    ASSERT_TRUE(re.success()) << "desk move " << draw << ": " << failures(re) << re.stats.reason;
    fell_back = replanner.last_report().fell_back;
    if (!fell_back) previous = re;
  }
  ASSERT_TRUE(fell_back) << "no desk move of 25 needed the fallback";
  EXPECT_EQ(replanner.last_report().method, "batch after incremental");
  // The answer is the incremental planner's warm-started solve of the moved problem (a batch
  // solve from the plan before the move, settled in the tree).
  const Plan warm = IncrementalPlanner(options.incremental).plan(moved, &previous);
  ASSERT_TRUE(warm.success());
  EXPECT_NEAR(re.stats.cost, warm.stats.cost, 1e-6 * warm.stats.cost);
  // The tree carries the recovered plan: the goal moved by a hair replans incrementally from it
  // (from the stalled result it would not validate).
  ProblemChange back;
  back.goal = moved.goal;
  back.goal->q += Eigen::VectorXd::Constant(7, 1e-4);
  const Plan next = replanner.replan(back);
  ASSERT_TRUE(next.success()) << failures(next);
  EXPECT_TRUE(replanner.last_report().incremental);
}

// Bad changes leave the planner as it was.
TEST(IncrementalPlanner, InvalidChangesAreRejected) {
  const Problem p = rr_problem();
  IncrementalPlanner planner;
  EXPECT_EQ(planner.set_goal(p.goal).stats.status, PlanStatus::kNoPlan);
  const Plan first = planner.plan(p);
  ASSERT_TRUE(first.success());
  EXPECT_EQ(planner.remove_obstacle(42).stats.status, PlanStatus::kInvalidProblem);
  Goal g;
  g.q = Eigen::Vector3d(0, 0, 0);  // wrong size
  EXPECT_EQ(planner.set_goal(g).stats.status, PlanStatus::kInvalidProblem);
  EXPECT_EQ(planner.problem().goal.q, p.goal.q);
  // Still usable afterwards.
  Goal ok;
  ok.q = Eigen::Vector2d(1.1, 0.7);
  EXPECT_TRUE(planner.set_goal(ok).success());
}

// Change files: the scene schema for goals, starts and obstacles; ids by scene name.
TEST(ReplanChange, ParsesGoalStartHorizonAndObstacles) {
  const Scene scene = load_scene(kScenes + "rr_reach.yaml");
  const SceneChange c = parse_change(
      "goal: {q: [1.0, 0.9]}\n"
      "start: {q: [-1.1, -0.5], qd: [0.1, 0]}\n"
      "horizon: 3.0\n"
      "obstacles:\n"
      "  - {id: ball, shape: sphere, size: [0.15], position: [0.3, 0, 1.5]}\n"
      "  - {id: pebble, shape: box, size: [0.1, 0.1, 0.1], position: [1, 0, 0.5]}\n",
      scene);
  ASSERT_TRUE(c.change.goal.has_value());
  EXPECT_TRUE(c.change.goal->q.isApprox(Eigen::Vector2d(1.0, 0.9)));
  EXPECT_TRUE(c.change.start_q->isApprox(Eigen::Vector2d(-1.1, -0.5)));
  EXPECT_TRUE(c.change.start_qd->isApprox(Eigen::Vector2d(0.1, 0)));
  EXPECT_EQ(*c.change.horizon, 3.0);
  ASSERT_EQ(c.change.add_or_move.size(), 2u);
  EXPECT_EQ(c.change.add_or_move[0].id, 0);  // the scene's ball, moved
  EXPECT_TRUE(c.change.add_or_move[0].pose.translation().isApprox(Eigen::Vector3d(0.3, 0, 1.5)));
  EXPECT_EQ(c.change.add_or_move[1].id, 1);  // new
  EXPECT_EQ(c.added_names, std::vector<std::string>{"pebble"});
  const Scene next = apply_change(scene, c);
  EXPECT_EQ(next.obstacle_names, (std::vector<std::string>{"ball", "pebble"}));
  EXPECT_EQ(next.problem.horizon, 3.0);

  const SceneChange r = parse_change("remove: [ball]", scene);
  EXPECT_EQ(r.change.remove, std::vector<int>{0});
  EXPECT_TRUE(apply_change(scene, r).problem.obstacles.empty());
}

TEST(ReplanChange, BadInputNamesTheKey) {
  const Scene scene = load_scene(kScenes + "rr_reach.yaml");
  auto key_of = [&scene](const std::string& yaml) {
    try {
      parse_change(yaml, scene, "change.yaml");
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("change.yaml"), std::string::npos) << e.what();
      return e.key();
    }
    return std::string("no error");
  };
  EXPECT_EQ(key_of("gaol: {q: [1, 1]}"), "gaol");
  EXPECT_EQ(key_of("remove: [nothing]"), "remove[0]");
  EXPECT_EQ(key_of("obstacles: [{shape: sphere, size: [0.1]}]"), "obstacles[0]");
  EXPECT_EQ(key_of("obstacles: [{id: ball, shape: sphere, size: [0.1]}]\nremove: [ball]"),
            "remove[0]");
  EXPECT_NE(key_of("goal: {q: [1, 2, 3]}"), "no error");
  EXPECT_NE(key_of("[1, 2"), "no error");
  // Keys and names that are not strings (a fuzzer's finding: yaml-cpp's conversion escaped).
  EXPECT_EQ(key_of("? {q: [1, 1]}\n: 2"), "");
  EXPECT_EQ(key_of("obstacles: [{id: {a: 1}, shape: sphere, size: [0.1]}]"), "obstacles[0].id");
  EXPECT_EQ(key_of("remove: [[ball]]"), "remove[0]");
  EXPECT_EQ(key_of("obstacles: [{id: \"b\xff\xfe\", shape: sphere, size: [0.1]}]"),
            "obstacles[0].id");  // not UTF-8: its written-back name was another one
  EXPECT_EQ(key_of("obstacles: [{id: \"ball ü 球 🎱\", shape: sphere, size: [0.1]}]"), "no error");
  EXPECT_THROW(load_change("/nonexistent/change.yaml", scene), SceneError);
}

// Every shipped change file parses for its scene and replans to a valid plan (RR ones).
TEST(ReplanChange, ShippedChangeFiles) {
  const Scene rr = load_scene(kScenes + "rr_reach.yaml");
  for (const char* name : {"rr_reach_goal", "rr_reach_move_ball", "rr_reach_start"}) {
    const SceneChange c = load_change(kScenes + "changes/" + name + ".yaml", rr);
    IncrementalPlanner planner;
    ASSERT_TRUE(planner.plan(rr.problem).success());
    const Plan re = planner.replan(c.change);
    EXPECT_TRUE(re.success()) << name << ": " << failures(re);
  }
  const Scene desk = load_scene(kScenes + "iiwa_desk.yaml");
  for (const char* name : {"iiwa_desk_goal", "iiwa_desk_add_box", "iiwa_desk_ball"}) {
    EXPECT_NO_THROW(load_change(kScenes + "changes/" + name + ".yaml", desk)) << name;
  }
}

}  // namespace
}  // namespace kinograph::planning

// validate() passes a consistent plan and catches each kind of violation on doctored copies.
#include "kinograph/planning/validate.h"

#include <gtest/gtest.h>

#include <cmath>

#include "kinograph/collision/collision_world.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/graph/worker_pool.h"
#include "kinograph/planning/formulation/initialization.h"
#include "kinograph/planning/formulation/planning_graph.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/problem_check.h"
#include "kinograph/planning/trajectory_sampler.h"

#include "tests/planning/test_problems.h"

namespace kinograph::planning {
namespace {

// The RR arm holding still at q* for 1 s: consistent, within limits, τ = gravity torque.
using Fixture = testing::StillRr;

bool mentions(const Validation& v, const std::string& what) {
  for (const auto& f : v.failures) {
    if (f.find(what) != std::string::npos) return true;
  }
  return false;
}

TEST(Validate, AcceptsAConsistentPlan) {
  Fixture f;
  const Validation v = validate(f.problem, f.plan);
  EXPECT_TRUE(v.valid) << (v.failures.empty() ? "" : v.failures.front());
  EXPECT_LT(v.max_dynamics_residual, 1e-9);
  EXPECT_EQ(v.goal_error, 0);
}

bool mentions_all(const Validation& v, std::initializer_list<std::string> parts) {
  for (const auto& f : v.failures) {
    bool all = true;
    for (const std::string& p : parts) all = all && f.find(p) != std::string::npos;
    if (all) return true;
  }
  return false;
}

std::string all_failures(const Validation& v) {
  std::string s;
  for (const auto& f : v.failures) s += " | " + f;
  return s;
}

// A 5 cm ball below the RR arm's base, out of its reach: an obstacle the walk must check.
collision::Obstacle ball_out_of_reach(int id) {
  collision::Obstacle ball;
  ball.id = id;
  ball.shape = collision::Shape::sphere(0.05);
  ball.pose.translation() = Eigen::Vector3d(0, 0, -1.5);
  return ball;
}

// A plan file with q = 1e308 made the collision walk run for ever; it now stops at its query
// bound and the plan is invalid, saying the rest was not checked.
TEST(Validate, APathTooLongToWalkIsInvalidNotEndless) {
  Fixture f;
  f.problem.obstacles.push_back(ball_out_of_reach(0));
  ASSERT_TRUE(validate(f.problem, f.plan).valid);
  f.plan.q(5, 0) = 1e308;
  const Validation v = validate(f.problem, f.plan);
  EXPECT_FALSE(v.valid);
  EXPECT_TRUE(mentions(v, "collision: not checked after t = ")) << all_failures(v);
}

// The physics and the pieces of the collision walk share the worker pool when it is free; run
// alone (inside a job, where the pool never helps) they give the same figures and failures.
TEST(Validate, TheSameVerdictWithAndWithoutThePoolsHelp) {
  const Problem desk =
      load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml").problem;
  // The straight line runs through the desk: collision, limit and dynamics failures to report.
  const Plan through = plan_from_trajectory(desk, straight_line(desk, desk.goal.q));
  const Validation shared = validate(desk, through);
  Validation alone;
  auto body = [&](int worker) {
    if (worker == 0) alone = validate(desk, through);
  };
  graph::run_on_workers(2, body);
  EXPECT_FALSE(shared.valid);
  EXPECT_LT(shared.min_clearance, 0);
  testing::expect_same_validation(shared, alone);
}

// A caller that asks only for the verdict (the replanner's stopping rule) gets the same figures
// for a clear plan, and for a colliding one the same failure from a walk that stopped at its
// first sample below the clearance.
TEST(Validate, TheVerdictAloneIsTheFullVerdict) {
  Fixture f;
  f.problem.obstacles.push_back(ball_out_of_reach(4));
  const Validation clear = validate(f.problem, f.plan);
  ASSERT_TRUE(clear.valid) << all_failures(clear);
  testing::expect_same_validation(clear, validate(f.problem, f.plan, {}, true));
  // The ball on the upper link, which holds still at 0.5 rad: every sample touches it.
  f.problem.obstacles[0].pose.translation() =
      Eigen::Vector3d(std::sin(0.5) * 0.5, 0, std::cos(0.5) * 0.5);
  const Validation full = validate(f.problem, f.plan);
  const Validation verdict = validate(f.problem, f.plan, {}, true);
  EXPECT_FALSE(verdict.valid);
  EXPECT_TRUE(mentions_all(verdict, {"collision: ", "obstacle 4 overlap"}))
      << all_failures(verdict);
  EXPECT_EQ(verdict.failures, full.failures);
  EXPECT_EQ(verdict.min_clearance, full.min_clearance);  // the first sample is the least here
}

// The collision walk is cut into pieces; a collision in a late piece is reported at its own
// time on the plan's clock.
TEST(Validate, ACollisionLateInThePlanIsReportedAtItsTime) {
  Fixture f;
  collision::Obstacle ball;  // on the upper link where the shoulder is at −0.5 rad
  ball.shape = collision::Shape::sphere(0.1);
  ball.pose.translation() = Eigen::Vector3d(std::sin(-0.5) * 0.5, 0, std::cos(-0.5) * 0.5);
  f.problem.obstacles.push_back(ball);
  ASSERT_GT(validate(f.problem, f.plan).min_clearance, 0);
  f.plan.q(8, 0) = -0.5;  // knot 8 (t = 0.8 s) swings into the ball and back
  const Validation v = validate(f.problem, f.plan);
  EXPECT_LT(v.min_clearance, 0);
  EXPECT_TRUE(mentions_all(v, {"collision: ", "at t = 0.8"})) << all_failures(v);
}

// The walk follows the interpolant, not the chords between its samples. The RR shoulder turns
// back between the samples at 0.4 and 0.5 s (equal there), 6.25 mrad beyond them; a ball just
// past the turn is touched only at the turn. The straight segments between the samples keep
// 7 mm from it.
TEST(Validate, ACollisionBetweenTheWalksSamplesIsFound) {
  testing::TurningRr f;
  Problem& problem = f.problem;
  const Plan& plan = f.plan;
  const double c = f.kC, turn = f.kTurn;
  // No self pairs: they would count the stray twice, as two geometries may both move.
  problem.self_and_floor.self_collision = false;
  // The tip ball (radius 0.045 at 1.8 m) 4 mm into a ball of radius 0.05 at the turn.
  const double beyond = 2 * std::asin(0.091 / 3.6);
  collision::Obstacle ball;
  ball.id = 3;
  ball.shape = collision::Shape::sphere(0.05);
  ball.pose.translation() =
      1.8 * Eigen::Vector3d(std::sin(turn + beyond), 0, std::cos(turn + beyond));
  problem.obstacles.push_back(ball);
  collision::CollisionWorld world(*problem.model);
  ASSERT_TRUE(world.add_obstacle(ball));
  dynamics::Data data(*problem.model);
  const auto distance = [&](double q0) {
    dynamics::forward_kinematics(*problem.model, data, Eigen::Vector2d(q0, 0));
    return world.closest(data).distance;
  };
  ASSERT_LT(distance(turn), -0.003);
  ASSERT_GT(distance(turn - c * 0.05 * 0.05 / 2), 0.006);  // the samples at 0.4 and 0.5 s
  const Validation v = validate(problem, plan);
  EXPECT_TRUE(mentions_all(v, {"collision: ", "obstacle 3 overlap"})) << all_failures(v);
  EXPECT_LT(v.min_clearance, -0.003);
  EXPECT_GT(v.min_clearance, -0.006);  // the bound is close: the stray is exact at the turn
}

// Start, goal and task failures say which joint or frame misses, by how much, and when.
TEST(Validate, StartGoalAndTaskFailuresNameJointFrameAndTime) {
  {
    Fixture f;
    f.problem.goal.q[1] += 0.2;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions_all(v, {"goal error", "joint 2 (joint2) ends at -0.3 rad, its goal is -0.1",
                                 "at t = 1 s"}))
        << all_failures(v);
  }
  {
    Fixture f;
    f.problem.start_q[0] += 0.05;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions_all(v, {"start state error", "joint 1 (joint1) position 0.5 rad instead of "
                                 "0.55", "at t = 0"}))
        << all_failures(v);
  }
  {
    Fixture f;
    f.plan.qd(10, 1) = 0.05;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions_all(v, {"final velocity", "joint 2 (joint2) velocity 0.05 rad/s",
                                 "at t = 1 s"}))
        << all_failures(v);
  }
  {
    Fixture f;
    dynamics::Data d(*f.problem.model);
    dynamics::forward_kinematics(*f.problem.model, d, f.problem.goal.q);
    TaskConstraint task;
    task.frame = "ee";
    task.target = dynamics::frame_pose(*f.problem.model, d, f.problem.model->frame_index("ee"));
    task.tolerance = 0.05;
    f.problem.task_constraints.push_back(task);
    f.plan.q(7, 0) += 0.3;  // the ee tilts by 0.3 rad at step 7 only (both joints turn about y)
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions_all(v, {"task constraint on 'ee'", "at t = 0.7 s"})) << all_failures(v);
  }
}

// A task constraint holds along the interpolant, not only at the knots: the RR arm's elbow
// swings out and back within one interval, so the ee, level at both knots, tilts by 1 rad
// half-way.
TEST(Validate, TaskConstraintsHoldBetweenTheKnots) {
  testing::SwingingRr f;
  Problem& p = f.problem;
  dynamics::Data d(*p.model);
  dynamics::forward_kinematics(*p.model, d, p.start_q);
  TaskConstraint level;
  level.frame = "ee";
  level.target = dynamics::frame_pose(*p.model, d, p.model->frame_index("ee"));
  level.tolerance = 0.05;
  p.task_constraints.push_back(level);
  const Validation v = validate(p, f.plan);
  EXPECT_TRUE(mentions_all(v, {"task constraint on 'ee' 1 exceeds 0.05", "at t = 0.5 s"}))
      << all_failures(v);
  EXPECT_NEAR(v.max_task_error, 1.0, 1e-9);
}

TEST(Validate, CatchesEachViolation) {
  {
    Fixture f;
    f.plan.tau(4, 1) += 0.1;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_FALSE(v.valid);
    EXPECT_TRUE(mentions(v, "dynamics"));
    EXPECT_NEAR(v.max_dynamics_residual, 0.1, 1e-9);
  }
  {
    Fixture f;
    f.plan.q(5, 0) += 0.1;  // a jump in q: the interpolant of interval 4 misses knot 5
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions(v, "position consistency"));
  }
  {
    Fixture f;
    f.plan.qd(5, 1) = 0.5;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions(v, "consistency"));
  }
  {
    Fixture f;
    f.problem.goal.q[1] += 0.2;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions(v, "goal"));
    EXPECT_NEAR(v.goal_error, 0.2, 1e-12);
  }
  {
    Fixture f;  // effort limit of joint 1 is 60 N·m
    f.plan.tau(3, 0) = 70;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions(v, "effort"));
    EXPECT_NEAR(v.max_tau_violation, 10, 1e-9);
  }
  {
    Fixture f;  // velocity limit 3 rad/s
    f.plan.qd(2, 0) = 3.5;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions(v, "velocity limit"));
    EXPECT_NEAR(v.max_qd_violation, 0.5, 1e-12);
  }
  {
    Fixture f;  // position limit ±π
    f.plan.q.col(0).setConstant(3.5);
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions(v, "position limit"));
  }
  {
    Fixture f;
    auto m = std::make_shared<dynamics::Model>(*f.problem.model);
    m->bodies[0].actuated = false;
    f.problem.model = m;
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions(v, "unactuated"));
  }
  {
    Fixture f;  // a ball on the arm
    collision::Obstacle ball;
    ball.shape = collision::Shape::sphere(0.1);
    ball.pose.translation() = Eigen::Vector3d(std::sin(0.5) * 0.5, 0, std::cos(0.5) * 0.5);
    f.problem.obstacles.push_back(ball);
    const Validation v = validate(f.problem, f.plan);
    EXPECT_TRUE(mentions(v, "collision"));
    EXPECT_LT(v.min_clearance, 0);
  }
  {
    Fixture f;
    f.plan.qdd(1, 1) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_FALSE(validate(f.problem, f.plan).valid);
    f.plan.q.resize(3, 2);
    EXPECT_FALSE(validate(f.problem, f.plan).valid);
  }
}

using testing::FastRr;

TEST(Validate, ChecksLimitsBetweenTheKnots) {
  FastRr f;
  const double v_knot = f.plan.qd.col(0).cwiseAbs().maxCoeff();  // hA/2 = 0.2 rad/s
  ASSERT_NEAR(v_knot, 0.2, 1e-12);
  const Validation ok = validate(f.problem, f.plan);
  ASSERT_TRUE(ok.valid) << ok.failures.front();
  EXPECT_LT(ok.max_position_consistency, 1e-12);
  // Limit 0.25 rad/s: every knot is within it, the motion between knots 1 and 2 is not.
  f.limit_velocity(0.25);
  const Validation v = validate(f.problem, f.plan);
  EXPECT_FALSE(v.valid);
  ASSERT_EQ(v.failures.size(), 1u);
  const std::string& why = v.failures.front();
  EXPECT_NE(why.find("velocity limit"), std::string::npos) << why;
  EXPECT_NE(why.find("joint 'joint1'"), std::string::npos) << why;
  EXPECT_NE(why.find("between knots 1 and 2"), std::string::npos) << why;
  // The peak is 0.3 rad/s at t = 0.15 s (the validator samples it at i·Δt/10).
  EXPECT_NEAR(v.max_qd_violation, 0.05, 1e-9);
  EXPECT_NE(why.find("t = 0.15 s"), std::string::npos) << why;
}

// Between the samples a joint's q peaks where its cubic turns, and is read there: the RR
// shoulder turns back at t = 0.45 s, 6.25 mrad beyond the samples at 0.4 and 0.5 s. With its
// upper limit 3 mrad below the turn, every sample is within it and the turn is not.
TEST(Validate, ALimitPassedBetweenTheSamplesIsFound) {
  testing::TurningRr f;
  Problem& p = f.problem;
  const Plan& plan = f.plan;
  auto model = std::make_shared<dynamics::Model>(*p.model);
  model->bodies[0].limits.upper = f.kTurn - 0.003;
  p.model = model;
  const Validation v = validate(p, plan);
  EXPECT_NEAR(v.max_q_violation, 0.003, 1e-12);
  EXPECT_TRUE(mentions_all(v, {"joint position limit violation (rad) 0.003", "joint 'joint1'",
                               "at t = 0.45 s (between knots 0 and 1)"}))
      << all_failures(v);
}

TEST(Validate, ChecksEffortBetweenTheKnots) {
  // The RR arm's shoulder swept at a constant 2 rad/s (q̈ = 0, elbow still) through the angle
  // of its largest gravity torque: the torque between the knots exceeds both knots' torques.
  Problem problem = testing::rr_reach();
  problem.obstacles.clear();
  dynamics::Data d(*problem.model);
  const auto gravity = [&](double q0) {
    return std::abs(
        dynamics::rnea(*problem.model, d, Eigen::Vector2d(q0, -0.3), Eigen::Vector2d(2, 0),
                       Eigen::Vector2d::Zero())[0]);
  };
  double peak = 0;
  for (double q0 = -M_PI; q0 < M_PI; q0 += 1e-3) peak = gravity(q0) > gravity(peak) ? q0 : peak;
  problem.steps = 1;
  problem.horizon = 0.2;
  Plan plan;
  plan.t = {0, 0.2};
  plan.q.resize(2, 2);
  plan.q << peak - 0.2, -0.3, peak + 0.2, -0.3;
  plan.qd.resize(2, 2);
  plan.qd << 2, 0, 2, 0;
  plan.qdd.setZero(2, 2);
  plan.tau.resize(2, 2);
  for (int k = 0; k < 2; ++k) {
    plan.tau.row(k) = dynamics::rnea(*problem.model, d, plan.q.row(k).transpose(),
                                     plan.qd.row(k).transpose(), plan.qdd.row(k).transpose())
                          .transpose();
  }
  problem.start_q = plan.q.row(0).transpose();
  problem.start_qd = plan.qd.row(0).transpose();
  problem.goal.q = plan.q.row(1).transpose();
  const double knot = plan.tau.col(0).cwiseAbs().maxCoeff(), between = gravity(peak);
  ASSERT_GT(between, knot + 0.01);
  auto m = std::make_shared<dynamics::Model>(*problem.model);
  m->bodies[0].limits.effort = 0.5 * (knot + between);
  problem.model = m;
  const Validation v = validate(problem, plan);
  EXPECT_FALSE(v.valid);
  EXPECT_EQ(v.max_tau_violation, 0);  // every knot is within the limit
  EXPECT_NEAR(v.max_tau_violation_between, 0.5 * (between - knot), 1e-3 * between);
  EXPECT_TRUE(mentions(v, "effort limit"));
  EXPECT_TRUE(mentions(v, "between knots 0 and 1"));
}

TEST(Validate, UnactuatedJointMustFollowTheDynamics) {
  // The Acrobot's shoulder between two knots that a cubic joins but the dynamics do not: the
  // shooting defect (continuity of the interpolant into knot 1) rejects it.
  Problem problem = testing::acrobot_swingup();
  problem.steps = 1;
  problem.horizon = 0.1;
  Plan plan;
  plan.t = {0, 0.1};
  plan.q.setZero(2, 2);
  plan.qd.setZero(2, 2);
  plan.qdd.setZero(2, 2);
  plan.tau.setZero(2, 2);
  plan.q.row(0) << 0.3, 0;  // released from 0.3 rad: the shoulder falls, the plan says it rests
  plan.q.row(1) << 0.3, 0;
  problem.start_q = plan.q.row(0).transpose();
  problem.goal.q = plan.q.row(1).transpose();
  dynamics::Data d(*problem.model);
  for (int k = 0; k < 2; ++k) {
    plan.tau.row(k) = dynamics::rnea(*problem.model, d, plan.q.row(k).transpose(),
                                     plan.qd.row(k).transpose(), plan.qdd.row(k).transpose())
                          .transpose();
  }
  const Validation v = validate(problem, plan);
  EXPECT_FALSE(v.valid);
  EXPECT_TRUE(mentions(v, "consistency")) << (v.failures.empty() ? "" : v.failures.front());
  EXPECT_TRUE(mentions(v, "joint 'shoulder'"));
}

// A goal's own tolerances replace the default goal threshold, per joint or per position and
// orientation; bad tolerances are refused by the problem check.
// The plan ends 0.005 rad from joint 2's goal: valid at the default 0.01, invalid at 0.001,
// and a tolerance on the other joint does not loosen or tighten joint 2's.
TEST(GoalTolerance, AJointToleranceIsThatJointsThreshold) {
  Fixture f;
  f.problem.goal.q[1] += 0.005;
  EXPECT_TRUE(validate(f.problem, f.plan).valid);
  f.problem.goal.joint_tolerance = Eigen::Vector2d(1e-4, 0);
  EXPECT_TRUE(validate(f.problem, f.plan).valid);
  f.problem.goal.joint_tolerance = Eigen::Vector2d(0, 1e-3);
  const Validation tight = validate(f.problem, f.plan);
  EXPECT_FALSE(tight.valid);
  EXPECT_TRUE(mentions(tight, "goal error 0.005 exceeds 0.001")) << tight.failures.front();
  EXPECT_TRUE(mentions(tight, "joint 2 (joint2)")) << tight.failures.front();
  EXPECT_NEAR(tight.goal_error, 0.005, 1e-12);
}

// 0.05 rad off: invalid by default, valid with a 0.06 rad tolerance on that joint.
TEST(GoalTolerance, ALooseJointToleranceAcceptsAFartherEnd) {
  Fixture f;
  f.problem.goal.q[0] -= 0.05;
  EXPECT_FALSE(validate(f.problem, f.plan).valid);
  f.problem.goal.joint_tolerance = Eigen::Vector2d(0.06, 0);
  EXPECT_TRUE(validate(f.problem, f.plan).valid);
}

// A pose goal 0.03 m from where the tip ends: the position tolerance decides.
TEST(GoalTolerance, APositionToleranceIsThePoseGoalsThreshold) {
  Fixture f;
  f.problem.goal = testing::tip_goal(f.problem, f.problem.start_q);
  f.problem.goal.pose.translation().x() += 0.03;
  const Validation by_default = validate(f.problem, f.plan);
  EXPECT_FALSE(by_default.valid);
  EXPECT_TRUE(mentions(by_default, "m from its goal position"));
  f.problem.goal.position_tolerance = 0.04;
  EXPECT_TRUE(validate(f.problem, f.plan).valid);
  f.problem.goal.position_tolerance = 0.02;
  EXPECT_FALSE(validate(f.problem, f.plan).valid);
}

// An orientation off by 0.1 rad about the arm's joint axis is judged by the orientation
// tolerance, unless the goal is position only.
TEST(GoalTolerance, AnOrientationToleranceIsThePoseGoalsRotationThreshold) {
  Fixture f;
  f.problem.goal = testing::tip_goal(f.problem, f.problem.start_q);
  f.problem.goal.position_only = false;
  f.problem.goal.pose.rotate(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()));
  const Validation by_default = validate(f.problem, f.plan);
  EXPECT_FALSE(by_default.valid);
  EXPECT_TRUE(mentions(by_default, "rad from its goal orientation"));
  f.problem.goal.orientation_tolerance = 0.11;
  EXPECT_TRUE(validate(f.problem, f.plan).valid);
}

TEST(GoalTolerance, BadTolerancesAreRefusedByTheProblemCheck) {
  Fixture f;
  EXPECT_EQ(check_problem(f.problem), "");
  f.problem.goal.joint_tolerance = Eigen::Vector3d(0.1, 0.1, 0.1);
  EXPECT_EQ(check_problem(f.problem), "joint goal tolerance has the wrong size");
  f.problem.goal.joint_tolerance = Eigen::Vector2d(0.1, -1);
  EXPECT_EQ(check_problem(f.problem), "the goal tolerance of joint 2 (joint2) must be a number >= 0");
  f.problem.goal.joint_tolerance.resize(0);
  f.problem.goal.position_tolerance = std::nan("");
  EXPECT_NE(check_problem(f.problem).find("tolerances must be numbers >= 0"), std::string::npos);
}

}  // namespace
}  // namespace kinograph::planning

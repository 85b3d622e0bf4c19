// The checks before any solve: the least time a joint needs under its limits (closed forms),
// impossible problems refused with the reason and the number, feasible ones at the bound let
// through; and violated rows of a graph described in the user's terms.
#include "kinograph/planning/problem_check.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/factors/dynamics_factors.h"
#include "kinograph/planning/formulation/dfg_builder.h"
#include "kinograph/planning/formulation/planning_graph.h"
#include "kinograph/planning/motion_bounds.h"
#include "kinograph/planning/solver/violation_text.h"
#include "kinograph/planning/user_terms.h"
#include "test_problems.h"

namespace kinograph::planning {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool has(const std::string& text, const std::string& needle) {
  return text.find(needle) != std::string::npos;
}

// Hand-worked profiles (V = vmax, A = amax).
TEST(MinTimeToRest, ClosedForms) {
  EXPECT_DOUBLE_EQ(min_time_to_rest(2, 0, 1, kInf), 2);     // d / V
  EXPECT_DOUBLE_EQ(min_time_to_rest(-2, 0.5, 1, kInf), 2);  // start velocity cannot help
  EXPECT_DOUBLE_EQ(min_time_to_rest(1, 0, kInf, 1), 2);     // triangle: 2√(d/A)
  EXPECT_DOUBLE_EQ(min_time_to_rest(4, 0, 1, 1), 5);        // d/V + V/A
  EXPECT_DOUBLE_EQ(min_time_to_rest(1, 1, 1, 1), 1.5);      // coast 0.5 s, brake 1 s
  EXPECT_NEAR(min_time_to_rest(0.1, 1, 1, 1), 1 + 2 * std::sqrt(0.4), 1e-12);  // overshoot
  EXPECT_DOUBLE_EQ(min_time_to_rest(1, -1, 1, 1), 1 + 2.5);  // stop, then 1.5 m from rest
  EXPECT_DOUBLE_EQ(min_time_to_rest(0, 0, 1, 1), 0);
  EXPECT_TRUE(std::isinf(min_time_to_rest(1, 0, 0, 1)));
  // Triangle with a start velocity: peak √(A d + u0²/2) = √1.5 below V = 2.
  EXPECT_NEAR(min_time_to_rest(1, 1, 2, 1), 2 * std::sqrt(1.5) - 1, 1e-12);
  EXPECT_DOUBLE_EQ(stopping_distance(2, 4), 0.5);
}

// The profile the bound stands for is achievable: full acceleration until the closed form's
// switch time, then full braking, reaches the distance exactly at rest at the bound.
TEST(MinTimeToRest, TriangleProfileReachesTheGoalAtRest) {
  const double d = 0.8, u0 = 0.3, A = 2.0, V = 10;
  const double T = min_time_to_rest(d, u0, V, A);
  const double vp = std::sqrt(A * d + 0.5 * u0 * u0), t1 = (vp - u0) / A, t2 = T - t1;
  const double v1 = u0 + A * t1;
  const double q = u0 * t1 + 0.5 * A * t1 * t1 + v1 * t2 - 0.5 * A * t2 * t2;
  EXPECT_NEAR(q, d, 1e-12);
  EXPECT_NEAR(v1 - A * t2, 0, 1e-12);
  EXPECT_LE(v1, V);
}

// The hidden case: joint 4 of the iiwa must cover 2.06 s worth of travel at its
// velocity limit in a 2 s horizon.
Problem iiwa_joint4_move(double horizon) {
  Problem p = testing::iiwa_swing(20);
  const double v4 = p.model->bodies[3].limits.velocity;
  p.start_q = Eigen::VectorXd::Zero(7);
  p.goal.q = Eigen::VectorXd::Zero(7);
  p.start_q[3] = -1.35;
  p.goal.q[3] = -1.35 + 2.06 * v4;
  p.horizon = horizon;
  return p;
}

// The same with joint 4's acceleration limited to 2 rad/s².
Problem iiwa_joint4_move_accel_limited(double horizon) {
  Problem p = iiwa_joint4_move(horizon);
  auto m = std::make_shared<dynamics::Model>(*p.model);
  m->bodies[3].limits.acceleration = 2.0;
  p.model = m;
  return p;
}

TEST(ProblemCheck, HorizonBelowTheVelocityBoundIsRefusedWithTheNumbers) {
  const Problem p = iiwa_joint4_move(2.0);
  const Plan plan = BatchPlanner().plan(p);
  EXPECT_EQ(plan.stats.status, PlanStatus::kInvalidProblem);
  EXPECT_EQ(plan.stats.iterations, 0);
  const std::string& why = plan.stats.reason;
  EXPECT_TRUE(has(why, "joint 4 (iiwa_joint_4)")) << why;
  EXPECT_TRUE(has(why, "needs 2.06 s at its velocity limit 1.31 rad/s")) << why;
  EXPECT_TRUE(has(why, "the horizon is 2 s")) << why;
}

TEST(ProblemCheck, HorizonExactlyAtTheBoundPasses) {
  Problem p = iiwa_joint4_move(2.0);
  const double bound = (p.goal.q[3] - p.start_q[3]) / p.model->bodies[3].limits.velocity;
  p.horizon = bound;
  EXPECT_EQ(check_problem(p), "");
  // Just below the bound: refused, with numbers that tell the two apart.
  p.horizon = bound * (1 - 1e-4);
  const std::string why = check_problem(p);
  EXPECT_TRUE(has(why, "needs " + number(bound, 5) + " s")) << why;
  EXPECT_TRUE(has(why, "the horizon is " + number(p.horizon, 5) + " s")) << why;
}

TEST(ProblemCheck, AccelerationLimitLengthensTheBound) {
  Problem p = iiwa_joint4_move_accel_limited(2.0);
  const double d = p.goal.q[3] - p.start_q[3], V = p.model->bodies[3].limits.velocity;
  const double bound = d / V + V / 2.0;  // coast at V between the two ramps
  p.horizon = bound;
  EXPECT_EQ(check_problem(p), "");
  p.horizon = 0.999 * bound;
  const std::string why = check_problem(p);
  EXPECT_TRUE(has(why, "acceleration limit 2 rad/s²")) << why;
  EXPECT_TRUE(has(why, "needs " + distinct_numbers(bound, p.horizon).first + " s")) << why;
}

// A start velocity towards the goal shortens the bound (never refuses a problem it makes
// feasible); one away from it lengthens it.
TEST(ProblemCheck, StartVelocityCountsBothWays) {
  Problem p = iiwa_joint4_move_accel_limited(2.0);
  const double d = p.goal.q[3] - p.start_q[3], V = p.model->bodies[3].limits.velocity;
  p.horizon = d / V + V / 2.0 - 0.1;  // below the bound from rest
  EXPECT_NE(check_problem(p), "");
  p.start_qd[3] = V;  // already at full speed: brake only, d/V + V/(2A)
  EXPECT_EQ(check_problem(p), "");
  p.start_qd[3] = -0.5;
  EXPECT_TRUE(has(check_problem(p), "from -0.5 rad/s")) << check_problem(p);
}

TEST(ProblemCheck, StartVelocityOverItsLimitOrUnableToStop) {
  Problem p = iiwa_joint4_move(5.0);
  p.start_qd[1] = 2.0;
  std::string why = check_problem(p);
  EXPECT_TRUE(has(why, "joint 2 (iiwa_joint_2) starts at 2 rad/s, beyond its velocity limit"))
      << why;
  p.start_qd[1] = 0;
  auto m = std::make_shared<dynamics::Model>(*p.model);
  m->bodies[0].limits.acceleration = 1.0;
  p.model = m;
  p.start_q[0] = m->bodies[0].limits.upper - 0.1;
  p.goal.q[0] = p.start_q[0];
  p.start_qd[0] = 1.0;  // needs 0.5 rad to stop, has 0.1
  why = check_problem(p);
  EXPECT_TRUE(has(why, "joint 1 (iiwa_joint_1) starts at 1 rad/s and needs 0.5 rad to stop"))
      << why;
  EXPECT_TRUE(has(why, "upper position limit is 0.1 rad away")) << why;
}

TEST(ProblemCheck, GoalOutsideTheLimitsNamesJointAndValue) {
  Problem p = iiwa_joint4_move(5.0);
  p.goal.q[2] = 3.5;
  const std::string why = check_problem(p);
  EXPECT_TRUE(has(why, "goal joint 3 (iiwa_joint_3) = 3.5 rad is outside its limits")) << why;
}

// Resting at the goal needs the gravity torque there: the Acrobot cannot rest with its arm
// horizontal (the unactuated shoulder would hold (m1 lc1 + m2 l1) g = 14.7 N·m, RNEA's figure);
// upright it can.
TEST(ProblemCheck, GoalThatGravityForbidsIsRefused) {
  Problem p = testing::acrobot_swingup();
  p.goal.q = Eigen::Vector2d(M_PI / 2, 0);
  dynamics::Data data(*p.model);
  const double hold =
      dynamics::rnea(*p.model, data, p.goal.q, Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero())[0];
  std::string why = check_problem(p);
  EXPECT_TRUE(has(why, "joint 1 (shoulder) is unactuated but would have to hold " + number(hold)))
      << why;
  p.goal.q = Eigen::Vector2d(M_PI, 0);
  EXPECT_EQ(check_problem(p), "");
  // The elbow at 90° carries its link: m2 lc2 g = 9.81 N·m over a 5 N·m limit (shoulder driven).
  auto m = std::make_shared<dynamics::Model>(*p.model);
  m->bodies[0].actuated = true;
  m->bodies[1].limits.effort = 5.0;
  p.model = m;
  p.goal.q = Eigen::Vector2d(0, M_PI / 2);
  why = check_problem(p);
  EXPECT_TRUE(has(why, "joint 2 (elbow) needs")) << why;
  EXPECT_TRUE(has(why, "over its 5 N·m effort limit")) << why;
}

// A graph's worst row in the user's terms: the RR arm's straight line with joint 1's effort
// limit far below its gravity load; the torque and time come from RNEA on the same trajectory.
TEST(ViolationText, TorqueRowNamesJointLimitExcessAndTime) {
  Problem p = testing::rr_reach();
  p.obstacles.clear();
  auto m = std::make_shared<dynamics::Model>(*p.model);
  m->bodies[0].limits.effort = 1.0;
  p.model = m;
  const Trajectory init = straight_line(p, p.goal.q);
  PlanningGraph pg = build_graph(p, init);
  std::vector<const FactorEntry*> at_knots;  // the torque rows at the knots, not between them
  for (const FactorEntry* e : pg.constraints(false)) {
    if (e->key.role == FactorRole::kDynamics) at_knots.push_back(e);
  }
  const ConstraintReport worst = worst_constraint(at_knots, pg.values);
  dynamics::Data data(*m);
  double excess = 0;
  int step = -1;
  for (int k = 0; k <= p.steps; ++k) {
    const Eigen::VectorXd tau =
        dynamics::rnea(*m, data, init.q.row(k).transpose(), init.qd.row(k).transpose(),
                       init.qdd.row(k).transpose());
    if (std::abs(tau[0]) - 1.0 > excess) {
      excess = std::abs(tau[0]) - 1.0;
      step = k;
    }
  }
  ASSERT_GE(step, 0);
  const std::string text = describe_violation(p, worst);
  EXPECT_TRUE(has(text, "joint 1 (joint1) torque")) << text;
  EXPECT_TRUE(has(text, "exceeds its 1 N·m limit by " + number(excess) + " N·m")) << text;
  EXPECT_TRUE(has(text, at_time(step * p.dt()))) << text;
}

TEST(ViolationText, CollisionRowNamesLinkAndObstacle) {
  Problem p = testing::rr_reach();  // its straight line runs through the ball (id 1)
  const Trajectory init = straight_line(p, p.goal.q);
  PlanningGraph pg = build_graph(p, init);
  std::vector<const FactorEntry*> collision;
  for (const FactorEntry* e : pg.constraints(false)) {
    if (e->key.role == FactorRole::kCollision) collision.push_back(e);
  }
  const ConstraintReport worst = worst_constraint(collision, pg.values);
  const std::string text = describe_violation(p, worst);
  EXPECT_TRUE(has(text, "link 'link")) << text;
  EXPECT_TRUE(has(text, "obstacle 1")) << text;
  EXPECT_TRUE(has(text, "t = ")) << text;
}

// Both formulations' torque rows map to the same joints: the Acrobot's passive shoulder is
// row 0 of the condensed factor and of the DFG's torque rows.
TEST(ViolationText, TorqueRowsOfBothFormulationsNameTheJoint) {
  Problem p = testing::acrobot_swingup();
  const auto workspace = std::make_shared<DynamicsWorkspace>(p.model);
  const FactorKey key{FactorRole::kDynamics, 55, 0, -1};
  const FactorEntry condensed = make_entry(
      std::make_shared<DynamicsStepFactor>(55, p.model, workspace, DynamicsStepOptions{}), key);
  const FactorEntry dfg =
      make_entry(std::make_shared<DfgTorqueRowsFactor>(*p.model, 55, DynamicsStepOptions{}), key);
  for (const FactorEntry* e : {&condensed, &dfg}) {
    ConstraintReport r;
    r.entry = e;
    r.row = 0;
    r.value = 0.166;
    r.violation = r.scaled_violation = 0.166;
    EXPECT_EQ(describe_violation(p, r),
              "joint 1 (shoulder) is unactuated but needs 0.166 N·m at "
              "t = 5.5 s");
    r.row = 1;  // the elbow's ±8 N·m bound
    r.value = -8.6;
    r.violation = r.scaled_violation = 0.6;
    EXPECT_EQ(describe_violation(p, r),
              "joint 2 (elbow) torque -8.6 N·m exceeds its 8 N·m limit by 0.6 N·m at t = 5.5 s");
  }
}

// The batch planner's failure reason is the same description, not solver internals.
TEST(ViolationText, InfeasibleSolveReasonSpeaksUserTerms) {
  Problem p = testing::acrobot_swingup();
  auto weak = std::make_shared<dynamics::Model>(*p.model);
  weak->bodies[1].limits.effort = 0.2;
  p.model = weak;
  BatchPlannerOptions o;
  o.outer_loop.max_total_iterations = 60;
  o.max_restarts = 0;
  o.effort_continuation.clear();
  const Plan plan = BatchPlanner(o).plan(p);
  ASSERT_EQ(plan.stats.status, PlanStatus::kInfeasible);
  const std::string& why = plan.stats.reason;
  EXPECT_TRUE(has(why, "joint 1 (shoulder)") || has(why, "joint 2 (elbow)")) << why;
  EXPECT_TRUE(has(why, "t = ")) << why;
  EXPECT_FALSE(has(why, "Factor")) << why;
}

}  // namespace
}  // namespace kinograph::planning

// Every option of the planning options structs is set by a test that fails when the option is
// ignored (the code behaving as with the default). One test per option or per point of use; each
// names the option it pins down. Small problems only (the RR arm), no timing.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/graph/factor_graph.h"
#include "kinograph/graph/values.h"
#include "kinograph/graph/worker_pool.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/factors/dynamics_factors.h"
#include "kinograph/planning/factors/state_target_factor.h"
#include "kinograph/planning/factors/trajectory_factors.h"
#include "kinograph/planning/formulation/dfg_builder.h"
#include "kinograph/planning/formulation/initialization.h"
#include "kinograph/planning/formulation/planning_graph.h"
#include "kinograph/planning/incremental/incremental_planner.h"
#include "kinograph/planning/interpolant.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/replanner.h"
#include "kinograph/planning/solver/augmented_lagrangian.h"
#include "kinograph/planning/solver/constraint_state.h"
#include "kinograph/planning/validate.h"
#include "tests/planning/test_problems.h"

namespace kinograph::planning {
namespace {

using testing::failures;

const std::string kScenes = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/";

bool mentions(const Validation& v, const std::string& what) {
  for (const auto& f : v.failures) {
    if (f.find(what) != std::string::npos) return true;
  }
  return false;
}

// The RR reach of robots/scenes/rr_reach.yaml (the ball above the upright pose).
Problem rr_scene() { return load_scene(kScenes + "rr_reach.yaml").problem; }

// The RR reach without its ball: one straight-line attempt, no detours.
Problem rr_free() {
  Problem p = testing::rr_reach();
  p.obstacles.clear();
  return p;
}

// ------------------------------------------------------------------------------------------
// GraphOptions: the scale s of each constraint family (rows are measured as z/s) and the
// collision query margin, read off a built graph.

// Scales of every constraint row of the entries with `role`.
std::vector<double> row_scales(const PlanningGraph& pg, FactorRole role) {
  std::vector<double> out;
  for (const FactorEntry& e : pg.entries) {
    if (e.key.role != role || !e.constrained) continue;
    for (const RowSpec& r : e.constrained->rows()) {
      if (r.kind != RowKind::kSoft) out.push_back(r.scale);
    }
  }
  return out;
}

// Every row of `role` in a graph built with `options` has `factor` times the scale it has
// with the default options.
void expect_scaled(const Problem& p, const GraphOptions& options, FactorRole role,
                   double factor) {
  const Trajectory init = straight_line(p, *goal_configuration(p));
  const std::vector<double> base = row_scales(build_graph(p, init), role);
  const std::vector<double> scaled = row_scales(build_graph(p, init, options), role);
  ASSERT_FALSE(base.empty());
  ASSERT_EQ(base.size(), scaled.size());
  for (size_t i = 0; i < base.size(); ++i) {
    EXPECT_NEAR(scaled[i], factor * base[i], 1e-12 * base[i]) << "row " << i;
  }
}

using testing::tip_goal;

TEST(GraphOptions, CollocationScale) {
  GraphOptions o;
  o.collocation_scale = 3.0;
  expect_scaled(rr_free(), o, FactorRole::kCollocation, 3.0);
}

TEST(GraphOptions, TorqueScale) {
  GraphOptions o;
  o.torque_scale = 4.0;
  expect_scaled(rr_free(), o, FactorRole::kDynamics, 4.0);
  // The DFG formulation's torque rows take the same scale.
  Problem p = rr_free();
  const Trajectory init = straight_line(p, p.goal.q);
  PlanningGraph pg = build_graph(p, init, o);
  use_dfg_dynamics(pg, p, o);
  int torque_rows = 0;
  for (const FactorEntry& e : pg.entries) {
    if (dynamic_cast<const DfgTorqueRowsFactor*>(e.constrained.get()) == nullptr) continue;
    for (const RowSpec& r : e.constrained->rows()) {
      EXPECT_EQ(r.scale, 4.0);
      ++torque_rows;
    }
  }
  EXPECT_GT(torque_rows, 0);
}

TEST(GraphOptions, LimitScale) {
  GraphOptions o;
  o.limit_scale = 0.5;
  expect_scaled(rr_free(), o, FactorRole::kLimits, 5.0);
}

TEST(GraphOptions, CollisionScale) {
  GraphOptions o;
  o.collision_scale = 0.06;
  expect_scaled(testing::rr_reach(), o, FactorRole::kCollision, 2.0);
}

TEST(GraphOptions, PoseScaleOfPoseGoalsAndTaskConstraints) {
  Problem p = rr_free();
  p.goal = tip_goal(p, p.goal.q);
  GraphOptions o;
  o.pose_scale = 0.05;
  expect_scaled(p, o, FactorRole::kGoal, 5.0);
  TaskConstraint keep;
  keep.frame = "ee";
  keep.orientation_only = true;
  keep.tolerance = 10;  // never binding: only the rows' scale matters here
  p.task_constraints.push_back(keep);
  expect_scaled(p, o, FactorRole::kTask, 5.0);
}

TEST(GraphOptions, CollisionQueryMargin) {
  const Problem p = testing::rr_reach();
  const Trajectory init = straight_line(p, p.goal.q);
  GraphOptions o;
  o.collision_query_margin = 0.25;
  const PlanningGraph pg = build_graph(p, init, o);
  ASSERT_EQ(pg.collision.count(-1), 1u);
  EXPECT_DOUBLE_EQ(pg.collision.at(-1)->query_distance, p.objectives.collision_epsilon + 0.25);
  const PlanningGraph inc = build_graph(p, init, o, GraphForm::kIncremental);
  ASSERT_EQ(inc.collision.count(p.obstacles[0].id), 1u);
  EXPECT_DOUBLE_EQ(inc.collision.at(p.obstacles[0].id)->query_distance,
                   p.objectives.collision_epsilon + 0.25);
  // Pairs beyond the query distance read as that distance: at the start (arm leaning left,
  // the ball far above the upright pose) the raw collision rows read exactly ε + margin with
  // margin 0, and more than that with the larger margin.
  GraphOptions tight;
  tight.collision_query_margin = 0;
  const PlanningGraph near = build_graph(p, init, tight);
  const PlanningGraph far = build_graph(p, init, o);
  auto first_collision_row = [&](const PlanningGraph& g) {
    for (const FactorEntry& e : g.entries) {
      if (e.key.role == FactorRole::kCollision && e.key.step == 1 && e.key.sub == 0) {
        Eigen::VectorXd z;
        e.constrained->values_at(g.values, z);
        return z.maxCoeff();
      }
    }
    return -1.0;
  };
  EXPECT_DOUBLE_EQ(first_collision_row(near), p.objectives.collision_epsilon);
  EXPECT_GT(first_collision_row(far), p.objectives.collision_epsilon + 0.01);
}

// ------------------------------------------------------------------------------------------
// DynamicsStepOptions: the rows of the condensed dynamics factor.

TEST(DynamicsStepOptions, LimitEpsilonTightensTheEffortBounds) {
  const auto model = testing::load_robot("robots/rr/rr.urdf");
  DynamicsStepOptions o;
  o.limit_epsilon = 5.0;
  const auto rows = DynamicsStepFactor::rows_for(*model, o);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].upper, 60.0 - 5.0);
  EXPECT_EQ(rows[0].lower, -(60.0 - 5.0));
  EXPECT_EQ(rows[1].upper, 30.0 - 5.0);
}

TEST(DynamicsStepOptions, MinTorqueAddsSoftRows) {
  const auto model = testing::load_robot("robots/rr/rr.urdf");
  DynamicsStepOptions o;
  o.min_torque = 0.5;
  auto ws = std::make_shared<DynamicsWorkspace>(model);
  const DynamicsStepFactor f(0, model, ws, o);
  ASSERT_EQ(f.rows().size(), 4u);  // two effort bounds, two soft rows
  EXPECT_EQ(f.rows()[2].kind, RowKind::kSoft);
  EXPECT_DOUBLE_EQ(f.rows()[3].weight, 1.0);  // √(2w)
  EXPECT_TRUE(f.has_soft_rows());
}

TEST(DynamicsStepOptions, TorqueScale) {
  const auto model = testing::load_robot("robots/rr/rr.urdf");
  DynamicsStepOptions o;
  o.torque_scale = 2.5;
  auto ws = std::make_shared<DynamicsWorkspace>(model);
  const DynamicsStepFactor f(0, model, ws, o);
  for (const RowSpec& r : f.rows()) EXPECT_EQ(r.scale, 2.5);
  // The violation of a row is measured in units of the scale.
  graph::Values v;
  v.insert(q_key(0), Eigen::Vector2d(0, 0));
  v.insert(v_key(0), Eigen::Vector2d(0, 0));
  v.insert(a_key(0), Eigen::Vector2d(100, 0));  // far beyond the shoulder's 60 N·m
  EXPECT_NEAR(f.scaled_violation(v), f.violation(v) / 2.5, 1e-9);
}

// ------------------------------------------------------------------------------------------
// DfgOptions and DfgKeys.

TEST(DfgOptions, KeysNameTheVariables) {
  const dynamics::Model m = *testing::load_robot("robots/rr/rr.urdf");
  DfgOptions o;
  o.keys.q = 'x';
  o.keys.qd = 'y';
  o.keys.qdd = 'z';
  o.keys.twist = 'W';
  o.keys.accel = 'B';
  o.keys.wrench = 'G';
  o.keys.torque = 'U';
  o.keys.torque_vector = true;
  const Eigen::Vector2d q(0.3, -0.4), qd(1.0, 0.5), qdd(-2.0, 1.0);
  graph::FactorGraph graph;
  graph::Values values;
  values.insert(o.keys.q_key(3), q);
  values.insert(o.keys.qd_key(3), qd);
  values.insert(o.keys.qdd_key(3), qdd);
  const DfgStep s = add_dfg_dynamics(graph, values, m, 3, o);
  for (int body = 0; body < 2; ++body) {
    EXPECT_TRUE(values.contains(graph::Key('W', body, 3)));
    EXPECT_TRUE(values.contains(graph::Key('B', body, 3)));
    EXPECT_TRUE(values.contains(graph::Key('G', body, 3)));
  }
  ASSERT_TRUE(values.contains(graph::Key('U', 0, 3)));
  EXPECT_EQ(values.at(graph::Key('U', 0, 3)).size(), 2);
  EXPECT_FALSE(values.contains(graph::Key('V', 0, 3)));
  EXPECT_FALSE(values.contains(graph::Key('T', 0, 3)));
  // The factors read the renamed joint variables: moving x(0,3) breaks the equations.
  EXPECT_LT(dfg_max_residual(graph, values, s.all()), 1e-10);
  dynamics::Data data(m);
  EXPECT_LT((dfg_torques(values, m, 3, o.keys) - dynamics::rnea(m, data, q, qd, qdd)).norm(),
            1e-10);
  values.at(o.keys.q_key(3))[1] += 0.2;
  EXPECT_GT(dfg_max_residual(graph, values, s.all()), 1e-3);
}

TEST(DfgOptions, SigmaWeighsTheFactors) {
  const dynamics::Model m = *testing::load_robot("robots/rr/rr.urdf");
  auto error_with = [&m](double sigma) {
    DfgOptions o;
    o.sigma = sigma;
    graph::FactorGraph graph;
    graph::Values values;
    values.insert(o.keys.q_key(0), Eigen::Vector2d(0.3, -0.4));
    values.insert(o.keys.qd_key(0), Eigen::Vector2d(1.0, 0.5));
    values.insert(o.keys.qdd_key(0), Eigen::Vector2d(-2.0, 1.0));
    add_dfg_dynamics(graph, values, m, 0, o);
    values.at(o.keys.torque_key(1, 0))[0] += 0.5;  // off the equations of motion
    return graph.error(values);
  };
  const double base = error_with(DfgOptions().sigma);
  ASSERT_GT(base, 0);
  EXPECT_NEAR(error_with(0.1) / base, std::pow(DfgOptions().sigma / 0.1, 2), 1e-9);
}

TEST(DfgOptions, ConstraintScaleOfTheEquationRows) {
  const auto model = testing::load_robot("robots/rr/rr.urdf");
  DfgOptions o;
  o.constraint_scale = 4.0;
  graph::FactorGraph graph;
  graph::Values values;
  values.insert(o.keys.q_key(0), Eigen::Vector2d(0.3, -0.4));
  values.insert(o.keys.qd_key(0), Eigen::Vector2d(1.0, 0.5));
  values.insert(o.keys.qdd_key(0), Eigen::Vector2d(-2.0, 1.0));
  dynamics::Data data(*model);
  const DfgConstraintStep s =
      add_dfg_constraints(graph, values, *model, data, 0, DynamicsStepOptions(), o);
  ASSERT_EQ(s.factors.size(), 4u * 2 + 1);
  values.at(o.keys.torque_key(1, 0))[0] += 0.5;  // the torque equation of joint 2 is off by 0.5
  double worst_scaled = 0, worst = 0;
  for (size_t i = 0; i < 8; ++i) {
    for (const RowSpec& r : s.factors[i]->rows()) EXPECT_EQ(r.scale, 4.0);
    worst_scaled = std::max(worst_scaled, s.factors[i]->scaled_violation(values));
    worst = std::max(worst, s.factors[i]->violation(values));
  }
  EXPECT_GT(worst, 0.1);
  EXPECT_NEAR(worst_scaled, worst / 4.0, 1e-12);
}

// DfgOptions::external is pinned by DfgBuilder.InitialValuesHaveZeroResidual (dfg_builder_test):
// the builder's torques equal RNEA with the wrenches.

// ------------------------------------------------------------------------------------------
// ValidationThresholds: each threshold decides its own check.

// The RR arm holding still at q* for 1 s over 10 steps (validate_test's fixture).
using Still = testing::StillRr;

TEST(ValidationThresholds, Dynamics) {
  Still f;
  f.plan.tau(4, 1) += 0.1;
  ASSERT_TRUE(mentions(validate(f.problem, f.plan), "dynamics"));
  ValidationThresholds t;
  t.dynamics = 0.2;
  const Validation v = validate(f.problem, f.plan, t);
  EXPECT_TRUE(v.valid) << v.failures.front();
}

TEST(ValidationThresholds, PositionConsistency) {
  Still f;
  f.plan.q.bottomRows(6).col(0).array() += 0.0005;  // a 0.5 mrad jump between steps 4 and 5
  f.problem.goal.q = f.plan.q.bottomRows(1).transpose();
  f.plan.tau.setZero();
  ValidationThresholds t;
  t.dynamics = 1e3;  // τ is off: only the consistency check matters here
  ASSERT_FALSE(mentions(validate(f.problem, f.plan, t), "position consistency"));
  t.position_consistency = 0.0002;
  EXPECT_TRUE(mentions(validate(f.problem, f.plan, t), "position consistency"));
}

TEST(ValidationThresholds, VelocityConsistency) {
  Still f;
  f.plan.qd(5, 1) = 0.005;
  ValidationThresholds t;
  ASSERT_FALSE(mentions(validate(f.problem, f.plan, t), "velocity consistency"));
  t.velocity_consistency = 0.001;
  EXPECT_TRUE(mentions(validate(f.problem, f.plan, t), "velocity consistency"));
}

TEST(ValidationThresholds, Limit) {
  Still f;
  f.plan.qd(2, 0) = 3.5;  // the velocity limit is 3 rad/s
  f.plan.tau(3, 1) = 30.5;  // the elbow's effort limit is 30 N·m
  ValidationThresholds t;
  t.dynamics = 1e3;
  t.velocity_consistency = 1e3;
  t.position_consistency = 1e3;
  const Validation strict = validate(f.problem, f.plan, t);
  ASSERT_TRUE(mentions(strict, "velocity limit"));
  ASSERT_TRUE(mentions(strict, "effort limit"));
  t.limit = 1.0;
  const Validation v = validate(f.problem, f.plan, t);
  EXPECT_TRUE(v.valid) << v.failures.front();
}

TEST(ValidationThresholds, UnactuatedTorque) {
  Still f;
  auto m = std::make_shared<dynamics::Model>(*f.problem.model);
  m->bodies[0].actuated = false;
  f.problem.model = m;
  const Validation strict = validate(f.problem, f.plan);
  ASSERT_TRUE(mentions(strict, "unactuated"));
  ValidationThresholds t;
  // The unpowered joint falls under gravity, away from the still plan: consistency is off too.
  t.position_consistency = 1e3;
  t.velocity_consistency = 1e3;
  t.unactuated_torque = 1e3;
  const Validation v = validate(f.problem, f.plan, t);
  EXPECT_TRUE(v.valid) << v.failures.front();
}

TEST(ValidationThresholds, MinClearance) {
  Still f;
  collision::Obstacle ball;  // 10 cm radius, 35 cm above the tip
  ball.shape = collision::Shape::sphere(0.1);
  dynamics::Data d(*f.problem.model);
  dynamics::forward_kinematics(*f.problem.model, d, f.plan.q.row(0).transpose());
  const Eigen::Vector3d tip =
      dynamics::frame_pose(*f.problem.model, d, f.problem.model->frame_index("ee")).translation();
  ball.pose.translation() = tip + Eigen::Vector3d(0, 0, 0.25 + 0.1);
  f.problem.obstacles.push_back(ball);
  const Validation loose = validate(f.problem, f.plan);
  ASSERT_TRUE(loose.valid) << loose.failures.front();
  ASSERT_GT(loose.min_clearance, 0.05);
  ValidationThresholds t;
  t.min_clearance = loose.min_clearance + 0.01;
  EXPECT_TRUE(mentions(validate(f.problem, f.plan, t), "collision"));
  // Negative: that much penetration is allowed.
  f.problem.obstacles[0].pose.translation() = tip;
  ASSERT_TRUE(mentions(validate(f.problem, f.plan), "collision"));
  t.min_clearance = -1.0;
  EXPECT_FALSE(mentions(validate(f.problem, f.plan, t), "collision"));
}

TEST(ValidationThresholds, Goal) {
  Still f;
  f.problem.goal.q[1] += 0.2;
  ASSERT_TRUE(mentions(validate(f.problem, f.plan), "goal"));
  ValidationThresholds t;
  t.goal = 0.3;
  const Validation v = validate(f.problem, f.plan, t);
  EXPECT_TRUE(v.valid) << v.failures.front();
}

TEST(ValidationThresholds, Start) {
  Still f;
  f.problem.start_q[0] += 1e-4;
  ASSERT_TRUE(mentions(validate(f.problem, f.plan), "start"));
  ValidationThresholds t;
  t.start = 1e-3;
  const Validation v = validate(f.problem, f.plan, t);
  EXPECT_TRUE(v.valid) << v.failures.front();
}

TEST(ValidationThresholds, FinalVelocity) {
  Still f;
  f.plan.qdd(f.problem.steps, 0) = 0.005;
  ValidationThresholds t;
  t.dynamics = 1e3;
  ASSERT_FALSE(mentions(validate(f.problem, f.plan, t), "final velocity"));
  t.final_velocity = 1e-3;
  EXPECT_TRUE(mentions(validate(f.problem, f.plan, t), "final velocity"));
}

// Between steps the validator walks the interpolant through collision_samples states per
// interval and bounds how far it strays between them: the elbow that swings out and back
// within one interval passes a ball that the straight segment between the two knots never
// comes near. Dense samples bound the overlap closely; one sample per interval still finds it,
// through a far looser bound.
TEST(ValidationThresholds, CollisionSamples) {
  testing::SwingingRr f;
  Problem& p = f.problem;
  const Plan& plan = f.plan;
  // Where the tip is half-way along the interpolant: elbow at 4 (s − s²) = 1 rad.
  dynamics::Data d(*p.model);
  dynamics::forward_kinematics(*p.model, d, Eigen::Vector2d(0, 1.0));
  collision::Obstacle ball;
  ball.shape = collision::Shape::sphere(0.1);
  ball.pose.translation() =
      dynamics::frame_pose(*p.model, d, p.model->frame_index("ee")).translation();
  p.obstacles.push_back(ball);
  ValidationThresholds t;
  ASSERT_GT(t.collision_samples, 1);
  const Validation dense = validate(p, plan, t);
  EXPECT_TRUE(mentions(dense, "collision"));
  EXPECT_LT(dense.min_clearance, -0.1);
  EXPECT_GT(dense.min_clearance, -0.2);  // tip ball 0.045 m, centred in the 0.1 m ball
  t.collision_samples = 1;
  const Validation sparse = validate(p, plan, t);
  EXPECT_TRUE(mentions(sparse, "collision"));
  EXPECT_LT(sparse.min_clearance, dense.min_clearance - 0.1);
}

TEST(ValidationThresholds, IntervalSamples) {
  testing::FastRr f;  // joint 0's q̇ is 0.2 rad/s at the knots and 0.3 between knots 1, 2
  f.limit_velocity(0.25);
  ValidationThresholds t;
  ASSERT_TRUE(mentions(validate(f.problem, f.plan, t), "velocity limit"));
  t.interval_samples = 1;  // the knots only
  const Validation v = validate(f.problem, f.plan, t);
  EXPECT_TRUE(v.valid) << v.failures.front();
}

// ------------------------------------------------------------------------------------------
// Objectives: the interior limit points of the planner's between-knot factor.

TEST(Objectives, LimitSubstepsArePointsOfTheIntervalFactor) {
  Problem p = rr_free();
  const auto interval_rows = [&](int substeps) {
    p.objectives.limit_substeps = substeps;
    const PlanningGraph pg = build_graph(p, straight_line(p, p.goal.q));
    int rows = 0, factors = 0;
    for (const FactorEntry& e : pg.entries) {
      if (e.key.role != FactorRole::kInterval) continue;
      rows += e.factor->residual_dim();
      ++factors;
    }
    EXPECT_EQ(factors, substeps > 0 ? p.steps : 0);
    return rows;
  };
  // The RR arm: per point each joint's τ, q and q̇ bounds; no unactuated joint, no defect rows.
  // Points are at least one per RK4 node of the interval (limit_points).
  EXPECT_EQ(interval_rows(0), 0);
  const int points = limit_points(3, p.dt());
  EXPECT_GE(points, 3);
  EXPECT_EQ(interval_rows(3), p.steps * points * 2 * 3);
  const int many = points + 5;
  EXPECT_EQ(interval_rows(many), p.steps * many * 2 * 3);
}

// ------------------------------------------------------------------------------------------
// AugmentedLagrangianOptions: the penalty schedule, on one equality row x = 0 (scale 1).

struct OneRow {
  std::shared_ptr<StateTargetFactor> factor = std::make_shared<StateTargetFactor>(
      std::vector<graph::Key>{q_key(0)}, 1, Eigen::VectorXd::Zero(1), 1.0);
  FactorEntry entry = make_entry(factor, {FactorRole::kGoal, 0});
  ConstraintState state;
  graph::Values at(double x) const {
    graph::Values v;
    v.insert(q_key(0), Eigen::VectorXd::Constant(1, x));
    return v;
  }
};

TEST(AugmentedLagrangianOptions, InitialPenalty) {
  OneRow r;
  AugmentedLagrangianOptions o;
  o.initial_penalty = 7;
  AugmentedLagrangian al({&r.entry}, r.state, o);
  EXPECT_EQ(al.penalty(), 7);
  EXPECT_EQ(r.state.penalty(), 7);
}

TEST(AugmentedLagrangianOptions, PenaltyGrowth) {
  OneRow r;
  AugmentedLagrangianOptions o;
  o.penalty_growth = 3;
  AugmentedLagrangian al({&r.entry}, r.state, o);
  al.update(r.at(1.0));
  al.update(r.at(1.0));  // the violation did not shrink: μ grows
  EXPECT_DOUBLE_EQ(al.penalty(), 3 * o.initial_penalty);
}

TEST(AugmentedLagrangianOptions, MaxPenalty) {
  OneRow r;
  AugmentedLagrangianOptions o;
  o.max_penalty = 150;
  AugmentedLagrangian al({&r.entry}, r.state, o);
  for (int i = 0; i < 4; ++i) al.update(r.at(1.0));
  EXPECT_DOUBLE_EQ(al.penalty(), 150);
}

TEST(AugmentedLagrangianOptions, RequiredDecrease) {
  OneRow r;
  AugmentedLagrangianOptions o;
  o.required_decrease = 0.6;
  AugmentedLagrangian al({&r.entry}, r.state, o);
  al.update(r.at(1.0));
  al.update(r.at(0.5));  // halved: enough for 0.6, not for the default 0.25
  EXPECT_DOUBLE_EQ(al.penalty(), o.initial_penalty);
  al.update(r.at(0.4));  // 0.8 of the last: too little
  EXPECT_DOUBLE_EQ(al.penalty(), o.initial_penalty * o.penalty_growth);
}

// ------------------------------------------------------------------------------------------
// DetourOptions: the via points of detour_candidates.

TEST(DetourOptions, CandidatesIsTheNumberDrawn) {
  const Problem p = testing::rr_reach();
  DetourOptions o;
  o.candidates = 5;
  EXPECT_EQ(detour_candidates(p, p.goal.q, o).size(), 5u);
}

TEST(DetourOptions, SpreadAroundTheMidpoint) {
  const Problem p = testing::rr_reach();
  const Eigen::VectorXd mid = 0.5 * (p.start_q + p.goal.q);
  DetourOptions o;
  o.spread = 0.1;
  double widest = 0;
  for (const Detour& d : detour_candidates(p, p.goal.q, o)) {
    widest = std::max(widest, (d.via - mid).cwiseAbs().maxCoeff());
  }
  EXPECT_LE(widest, 0.1);
  EXPECT_GT(widest, 0.05);
}

TEST(DetourOptions, SeedDrawsOtherViaPoints) {
  const Problem p = testing::rr_reach();
  DetourOptions o;
  o.seed = 7;
  const std::vector<Detour> a = detour_candidates(p, p.goal.q, o);
  const std::vector<Detour> b = detour_candidates(p, p.goal.q, o);
  const std::vector<Detour> base = detour_candidates(p, p.goal.q);
  ASSERT_EQ(a.size(), base.size());
  double same_seed = 0, other_seed = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    same_seed = std::max(same_seed, (a[i].via - b[i].via).cwiseAbs().maxCoeff());
    other_seed = std::max(other_seed, (a[i].via - base[i].via).cwiseAbs().maxCoeff());
  }
  EXPECT_EQ(same_seed, 0.0) << "repeatable";
  EXPECT_GT(other_seed, 0.1);
}

// The paths are checked on the process's workers; the ranking is the one a single worker makes
// (a job inside a job runs on its caller alone).
TEST(DetourOptions, RankingIsTheSameOnOneWorker) {
  const Problem p = testing::rr_reach();
  const std::vector<Detour> shared = detour_candidates(p, p.goal.q);
  std::vector<Detour> alone;
  auto body = [&](int worker) {
    if (worker == 0) alone = detour_candidates(p, p.goal.q);
  };
  graph::run_on_workers(2, body);
  ASSERT_EQ(alone.size(), shared.size());
  for (size_t i = 0; i < shared.size(); ++i) {
    EXPECT_EQ(alone[i].via, shared[i].via) << i;
    EXPECT_EQ(alone[i].clearance, shared[i].clearance) << i;
  }
}

// Asked for the `best` best, the ranking gives up on candidates that cannot be among them: what
// it returns must be exactly the head of the full ranking (via points, clearances, order), on
// the desk, for goals around it, on two workers or one.
TEST(DetourOptions, TheBestAreTheHeadOfTheFullRanking) {
  Problem p = load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml").problem;
  std::mt19937 rng(11);
  int compared = 0;
  for (int goal = 0; goal < 8; ++goal) {
    Eigen::VectorXd g = p.goal.q;
    for (int j = 0; j < g.size(); ++j) g[j] += std::uniform_real_distribution<double>(-0.6, 0.6)(rng);
    const std::vector<Detour> all = detour_candidates(p, g);
    ASSERT_EQ(all.size(), static_cast<size_t>(DetourOptions().candidates));
    for (int best : {1, 3, 4, 30}) {
      std::vector<Detour> head = detour_candidates(p, g, {}, best), alone;
      auto body = [&](int worker) {
        if (worker == 0) alone = detour_candidates(p, g, {}, best);
      };
      graph::run_on_workers(2, body);
      ASSERT_EQ(head.size(), std::min(all.size(), static_cast<size_t>(best)));
      ASSERT_EQ(alone.size(), head.size());
      for (size_t i = 0; i < head.size(); ++i, ++compared) {
        EXPECT_EQ(head[i].via, all[i].via) << "goal " << goal << " best " << best << " " << i;
        EXPECT_EQ(head[i].clearance, all[i].clearance) << "goal " << goal << " " << i;
        EXPECT_EQ(alone[i].via, all[i].via) << "goal " << goal << " best " << best << " " << i;
      }
    }
  }
  EXPECT_EQ(compared, 8 * (1 + 3 + 4 + 24));
  EXPECT_TRUE(detour_candidates(p, p.goal.q, {}, 0).empty());
}

// Each detour's clearance is that of its two segments sampled `samples` times, capped at ε.
TEST(DetourOptions, SamplesPerSegment) {
  const Problem p = testing::rr_reach();
  DetourOptions o;
  o.samples = 2;
  int differs = 0;
  for (const Detour& d : detour_candidates(p, p.goal.q, o)) {
    auto along = [&](int samples) {
      return std::min({segment_clearance(p, p.start_q, d.via, samples),
                       segment_clearance(p, d.via, p.goal.q, samples),
                       p.objectives.collision_epsilon});
    };
    EXPECT_DOUBLE_EQ(d.clearance, along(2));
    differs += along(2) != along(DetourOptions().samples);
  }
  EXPECT_GT(differs, 0) << "the sample count must matter for this problem";
}

// ------------------------------------------------------------------------------------------
// BatchPlannerOptions.

// The straight-line plan of the RR reach: no detours at all.
Plan straight_line_plan(const Problem& p) {
  BatchPlannerOptions o;
  o.max_restarts = 0;
  return BatchPlanner(o).plan(p);
}

double max_abs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }

TEST(BatchPlannerOptions, FormulationDfg) {
  BatchPlannerOptions o;
  o.formulation = Formulation::kDynamicFactorGraph;
  BatchSolution s;
  const Plan plan = BatchPlanner(o).plan(rr_free(), nullptr, &s);
  ASSERT_TRUE(plan.success()) << failures(plan);
  EXPECT_TRUE(s.graph.values.contains(graph::Key('T', 1, 5)));  // the DFG's τ variables
  // Its τ are those variables, not RNEA of the trajectory: a small but nonzero residual.
  EXPECT_GT(plan.validation.max_dynamics_residual, 0.0);
}

TEST(BatchPlannerOptions, DfgKeysOfThePlannersGraph) {
  BatchPlannerOptions o;
  o.formulation = Formulation::kDynamicFactorGraph;
  o.dfg.keys.torque_vector = true;
  o.dfg.keys.wrench = 'W';
  BatchSolution s;
  const Plan plan = BatchPlanner(o).plan(rr_free(), nullptr, &s);
  ASSERT_TRUE(plan.success()) << failures(plan);
  ASSERT_TRUE(s.graph.values.contains(graph::Key('T', 0, 5)));
  EXPECT_EQ(s.graph.values.at(graph::Key('T', 0, 5)).size(), 2);
  EXPECT_FALSE(s.graph.values.contains(graph::Key('T', 1, 5)));
  EXPECT_TRUE(s.graph.values.contains(graph::Key('W', 1, 5)));
  EXPECT_FALSE(s.graph.values.contains(graph::Key('F', 1, 5)));
}

// A constant wrench on the forearm enters the DFG's wrench balance: the plan's τ (the DFG's
// variables) are RNEA's with that wrench, which the validator (knowing no external wrenches)
// reports as a dynamics residual of the wrench's joint torques.
TEST(BatchPlannerOptions, DfgExternalWrench) {
  const Problem p = rr_free();
  BatchPlannerOptions o;
  o.formulation = Formulation::kDynamicFactorGraph;
  dynamics::ExternalWrench push;
  push.body = 1;
  push.wrench << 0, 0, 0, 5, 0, 0;  // 5 N along the forearm's x
  o.dfg.external = {push};
  o.validation.dynamics = 1e3;
  const Plan plan = BatchPlanner(o).plan(p);
  ASSERT_EQ(plan.stats.status, PlanStatus::kConverged) << failures(plan);
  dynamics::Data data(*p.model);
  double with = 0, without = 0;
  for (int k = 0; k <= p.steps; ++k) {
    const Eigen::VectorXd q = plan.q.row(k).transpose(), qd = plan.qd.row(k).transpose(),
                          qdd = plan.qdd.row(k).transpose();
    const Eigen::VectorXd tau = plan.tau.row(k).transpose();
    with = std::max(with, max_abs(tau - dynamics::rnea(*p.model, data, q, qd, qdd, o.dfg.external)));
    without = std::max(without, max_abs(tau - dynamics::rnea(*p.model, data, q, qd, qdd)));
  }
  EXPECT_LT(with, 1e-3);
  EXPECT_GT(without, 1.0);
}

TEST(BatchPlannerOptions, DfgConstraintTolerance) {
  BatchPlannerOptions o;
  o.formulation = Formulation::kDynamicFactorGraph;
  o.dfg_constraint_tolerance = 1e-8;
  EXPECT_EQ(outer_loop_options(o).constraint_tolerance, 1e-8);
  const Plan plan = BatchPlanner(o).plan(rr_free());
  ASSERT_EQ(plan.stats.status, PlanStatus::kConverged) << failures(plan);
  // Every row's scale is at most 1: the own-units violation is below the scaled tolerance.
  EXPECT_LT(plan.stats.max_constraint_violation, 1e-8);
}

TEST(BatchPlannerOptions, DfgInnerToleranceFinal) {
  BatchPlannerOptions o;
  o.formulation = Formulation::kDynamicFactorGraph;
  o.dfg_inner_tolerance_final = 1e-3;
  EXPECT_EQ(outer_loop_options(o).inner_tolerance_final, 1e-3);
  BatchPlannerOptions tight = o;
  tight.dfg_inner_tolerance_final = 1e-9;
  EXPECT_EQ(outer_loop_options(tight).inner_tolerance_final, 1e-9);
  const Plan loose = BatchPlanner(o).plan(rr_free());
  const Plan polished = BatchPlanner(tight).plan(rr_free());
  ASSERT_TRUE(loose.success()) << failures(loose);
  ASSERT_TRUE(polished.success()) << failures(polished);
  EXPECT_LT(loose.stats.iterations, polished.stats.iterations);
}

TEST(BatchPlannerOptions, GraphScalesReachThePlannersGraph) {
  BatchPlannerOptions o;
  o.graph.limit_scale = 0.5;
  BatchSolution s;
  const Plan plan = BatchPlanner(o).plan(rr_free(), nullptr, &s);
  ASSERT_TRUE(plan.success()) << failures(plan);
  const std::vector<double> scales = row_scales(s.graph, FactorRole::kLimits);
  ASSERT_FALSE(scales.empty());
  for (double x : scales) EXPECT_EQ(x, 0.5);
}

// The augmented-Lagrangian schedule of the batch solve, read from its final μ (on the RR reach
// without the ball the default schedule grows μ from 100 to 1000).
double final_penalty(const BatchPlannerOptions& o) {
  BatchSolution s;
  BatchPlanner(o).plan(rr_free(), nullptr, &s);
  return s.constraints.penalty();
}

TEST(BatchPlannerOptions, AugmentedLagrangianSchedule) {
  ASSERT_GT(final_penalty(BatchPlannerOptions()), 100);
  {
    BatchPlannerOptions o;
    o.augmented_lagrangian.initial_penalty = 1e4;
    EXPECT_GE(final_penalty(o), 1e4);
  }
  {
    BatchPlannerOptions o;
    o.augmented_lagrangian.max_penalty = 100;
    EXPECT_EQ(final_penalty(o), 100);
  }
  {
    BatchPlannerOptions o;
    o.augmented_lagrangian.penalty_growth = 3;
    const double k = std::log(final_penalty(o) / 100) / std::log(3.0);  // μ = 100·3^k
    EXPECT_GE(k, 1 - 1e-9);
    EXPECT_NEAR(k, std::round(k), 1e-9);
  }
  {
    BatchPlannerOptions o;
    o.augmented_lagrangian.required_decrease = 0.9;
    EXPECT_EQ(final_penalty(o), 100);
  }
}

TEST(OuterLoopOptions, ConstraintTolerance) {
  BatchPlannerOptions o;
  o.outer_loop.constraint_tolerance = 1e-6;
  const Plan plan = BatchPlanner(o).plan(rr_free());
  ASSERT_EQ(plan.stats.status, PlanStatus::kConverged) << failures(plan);
  EXPECT_LT(plan.stats.max_constraint_violation, 1e-6);
}

TEST(OuterLoopOptions, MaxOuterIterations) {
  BatchPlannerOptions o;
  o.outer_loop.max_outer_iterations = 1;
  const Plan plan = BatchPlanner(o).plan(rr_free());
  EXPECT_EQ(plan.stats.outer_iterations, 1);
  EXPECT_EQ(plan.stats.status, PlanStatus::kInfeasible);
}

TEST(OuterLoopOptions, MaxInnerIterations) {
  BatchPlannerOptions o;
  o.outer_loop.max_inner_iterations = 1;
  const Plan plan = BatchPlanner(o).plan(rr_free());
  EXPECT_GT(plan.stats.outer_iterations, 0);
  EXPECT_EQ(plan.stats.iterations, plan.stats.outer_iterations);
}

TEST(OuterLoopOptions, MaxTotalIterations) {
  BatchPlannerOptions o;
  o.outer_loop.max_total_iterations = 5;
  const Plan plan = BatchPlanner(o).plan(rr_free());
  EXPECT_LE(plan.stats.iterations, 5);
  EXPECT_EQ(plan.stats.status, PlanStatus::kInfeasible);
}

// The first inner solve stops at a relative decrease below inner_tolerance_initial.
TEST(OuterLoopOptions, InnerToleranceInitial) {
  BatchPlannerOptions o;
  o.outer_loop.max_outer_iterations = 1;
  o.outer_loop.max_inner_iterations = 100;
  ASSERT_GT(BatchPlanner(o).plan(rr_free()).stats.iterations, 5);
  o.outer_loop.inner_tolerance_initial = 0.5;
  EXPECT_LE(BatchPlanner(o).plan(rr_free()).stats.iterations, 2);
}

// Feasible at once (a huge constraint tolerance): the loop ends as soon as an inner solve ran at
// the final tolerance — the second one by default, the first when that tolerance is as loose as
// the initial one.
TEST(OuterLoopOptions, InnerToleranceFinal) {
  BatchPlannerOptions o;
  o.outer_loop.constraint_tolerance = 10;
  ASSERT_EQ(BatchPlanner(o).plan(rr_free()).stats.outer_iterations, 2);
  o.outer_loop.inner_tolerance_final = 1.0;
  const Plan plan = BatchPlanner(o).plan(rr_free());
  EXPECT_EQ(plan.stats.status, PlanStatus::kConverged);
  EXPECT_EQ(plan.stats.outer_iterations, 1);
}

// The Acrobot's warm-up re-solve runs its inner solves at the largest μ: carrying LM's damping
// from one to the next saves linearizations that restarting at λ₀ spends.
TEST(OuterLoopOptions, DampingCarry) {
  const Problem p = load_scene(kScenes + "acrobot_swingup.yaml").problem;
  BatchPlannerOptions o;
  const Plan carried = BatchPlanner(o).plan(p);
  o.outer_loop.damping_carry = 0;
  const Plan restarted = BatchPlanner(o).plan(p);
  ASSERT_TRUE(carried.success()) << failures(carried);
  ASSERT_TRUE(restarted.success()) << failures(restarted);
  EXPECT_LT(carried.stats.iterations, restarted.stats.iterations);
}

// At the largest penalty the weak elbow's violation stops shrinking, and the loop gives up
// after max_stalled_updates such updates instead of running to max_outer_iterations.
TEST(OuterLoopOptions, MaxStalledUpdates) {
  BatchPlannerOptions o;
  const Problem p = testing::weak_elbow_acrobot(o);
  const Plan stalled = BatchPlanner(o).plan(p);
  o.outer_loop.max_stalled_updates = 0;
  const Plan ran_on = BatchPlanner(o).plan(p);
  for (const Plan* plan : {&stalled, &ran_on}) {
    EXPECT_FALSE(plan->success());
    EXPECT_EQ(plan->stats.status, PlanStatus::kInfeasible);
  }
  EXPECT_LT(stalled.stats.outer_iterations, ran_on.stats.outer_iterations);
}

// The weak elbow's knot-only solve stalls far from feasible (a worst scaled violation
// of about 1.4), so with abandon_violation = 1 the attempt ends there; with 0 it goes on to the
// warm-up and the rows on the interpolant, which stall too. Both report the failure.
TEST(BatchPlannerOptions, AbandonViolation) {
  BatchPlannerOptions o;
  const Problem p = testing::weak_elbow_acrobot(o);
  o.abandon_violation = 1;
  const Plan abandoned = BatchPlanner(o).plan(p);
  o.abandon_violation = 0;
  const Plan went_on = BatchPlanner(o).plan(p);
  for (const Plan* plan : {&abandoned, &went_on}) {
    EXPECT_FALSE(plan->success());
    EXPECT_EQ(plan->stats.status, PlanStatus::kInfeasible);
    EXPECT_FALSE(plan->stats.reason.empty());
  }
  EXPECT_GT(abandoned.stats.max_constraint_violation, 0);
  EXPECT_LT(2 * abandoned.stats.iterations, went_on.stats.iterations);
  // The default is above the stalled violation: the attempt goes on.
  o.abandon_violation = BatchPlannerOptions().abandon_violation;
  EXPECT_EQ(BatchPlanner(o).plan(p).stats.iterations, went_on.stats.iterations);
}

TEST(BatchPlannerOptions, ValidationThresholdsJudgeThePlan) {
  BatchPlannerOptions o;
  o.validation.final_velocity = -1;  // no plan can meet this
  const Plan plan = BatchPlanner(o).plan(rr_free());
  EXPECT_EQ(plan.stats.status, PlanStatus::kConverged);
  EXPECT_FALSE(plan.success());
  EXPECT_TRUE(mentions(plan.validation, "final velocity"));
}

// With plans that never validate, every initialization allowed is tried: the straight line and
// max_restarts detours (at most detour.candidates of them).
TEST(BatchPlannerOptions, MaxRestarts) {
  BatchPlannerOptions o;
  o.validation.final_velocity = -1;
  ASSERT_EQ(BatchPlanner(o).plan(testing::rr_reach()).stats.attempts, 1 + o.max_restarts);
  o.max_restarts = 2;
  EXPECT_EQ(BatchPlanner(o).plan(testing::rr_reach()).stats.attempts, 3);
  o.max_restarts = 0;
  EXPECT_EQ(BatchPlanner(o).plan(testing::rr_reach()).stats.attempts, 1);
}

// A short, coarse Acrobot swing-up whose plans never validate: the continuation in the effort
// limits runs after the straight line (one attempt more), once per factor of
// effort_continuation. Short, since each interval integrates the shoulder in 0.01 s steps.
Problem never_valid_acrobot(BatchPlannerOptions& o) {
  o.validation.final_velocity = -1;  // no plan can meet this
  o.effort_continuation = {2};
  Problem p = testing::acrobot_swingup();
  p.horizon = 3;
  p.steps = 6;
  return p;
}

TEST(BatchPlannerOptions, EffortContinuationRunsForUnactuatedRobots) {
  BatchPlannerOptions o;
  const Problem p = never_valid_acrobot(o);
  ASSERT_EQ(BatchPlanner(o).plan(p).stats.attempts, 2);
  o.effort_continuation.clear();
  EXPECT_EQ(BatchPlanner(o).plan(p).stats.attempts, 1);
}

// No stage validates, so each one and the final solve start from the straight line: the final
// solve repeats the first attempt (`none` iterations) and each factor adds a stage of its own.
TEST(BatchPlannerOptions, EffortContinuationSolvesEachFactor) {
  BatchPlannerOptions o;
  const Problem p = never_valid_acrobot(o);
  const int one = BatchPlanner(o).plan(p).stats.iterations;  // {2}
  o.effort_continuation = {2, 1.5};
  const int two = BatchPlanner(o).plan(p).stats.iterations;
  o.effort_continuation.clear();
  const int none = BatchPlanner(o).plan(p).stats.iterations;
  EXPECT_GT(one, 2 * none);
  EXPECT_GT(two, one);
}

// The RR reach at 3 s: 120 steps are planned from 60 and 30 steps by default (one attempt per
// grid), from 60 only when grids of 0.1 s intervals are too coarse, and directly when off.
TEST(BatchPlannerOptions, RefineMaxInterval) {
  Problem p = testing::rr_reach();
  p.steps = 120;
  BatchPlannerOptions o;
  const Plan by_default = BatchPlanner(o).plan(p);
  o.refine_max_interval = 0.05;
  const Plan finer = BatchPlanner(o).plan(p);
  o.refine_max_interval = 0;
  const Plan direct = BatchPlanner(o).plan(p);
  for (const Plan* plan : {&by_default, &finer, &direct}) {
    EXPECT_TRUE(plan->success()) << plan->stats.reason;
    EXPECT_EQ(plan->q.rows(), 121);
  }
  EXPECT_EQ(by_default.stats.attempts, 3);
  EXPECT_EQ(finer.stats.attempts, 2);
  EXPECT_EQ(direct.stats.attempts, 1);
}

TEST(BatchPlannerOptions, DetourCandidatesBoundTheRestarts) {
  BatchPlannerOptions o;
  o.validation.final_velocity = -1;
  o.path_search.max_samples = 0;  // the detours only
  o.detour.candidates = 1;
  EXPECT_EQ(BatchPlanner(o).plan(testing::rr_reach()).stats.attempts, 2);
}

// The straight line of the RR reach runs through the ball; by default the best detour goes
// first (and validates, passing the ball on the other side from the straight line's plan).
TEST(BatchPlannerOptions, DetourFirst) {
  const Problem p = testing::rr_reach();
  const Plan straight = straight_line_plan(p);
  ASSERT_TRUE(straight.success()) << failures(straight);
  ASSERT_GT(max_abs(BatchPlanner().plan(p).q - straight.q), 0.1);
  BatchPlannerOptions o;
  o.detour_first = false;
  const Plan plan = BatchPlanner(o).plan(p);
  EXPECT_EQ(plan.stats.attempts, 1);
  EXPECT_EQ(max_abs(plan.q - straight.q), 0.0) << "the straight line went first";
}

// The detour seed of the batch planner: other via points, another plan.
TEST(BatchPlannerOptions, DetourSeed) {
  const Problem p = testing::rr_reach();
  BatchPlannerOptions o;
  o.detour.seed = 7;
  const Plan plan = BatchPlanner(o).plan(p);
  ASSERT_TRUE(plan.success()) << failures(plan);
  EXPECT_GT(max_abs(plan.q - BatchPlanner().plan(p).q), 1e-3);
}

// The straight line's collision check (2·samples segments) decides whether a detour goes
// first: with one sample only the start and the goal are checked, both clear.
TEST(BatchPlannerOptions, DetourSamplesOfTheStraightLineCheck) {
  const Problem p = testing::rr_reach();
  BatchPlannerOptions o;
  o.detour.samples = 0;
  EXPECT_EQ(max_abs(BatchPlanner(o).plan(p).q - straight_line_plan(p).q), 0.0);
}

// ------------------------------------------------------------------------------------------
// IncrementalPlannerOptions.

// The RR reach planned, then a goal far across (the elbow raised): a replan of several ISAM2
// updates, one multiplier round when converged (stop_at_first_valid false).
Goal far_goal() {
  Goal g;
  g.q = Eigen::Vector2d(0.3, 1.5);
  return g;
}

TEST(IncrementalPlannerOptions, BatchOptionsJudgeTheReplans) {
  IncrementalPlannerOptions o;
  o.batch.validation.goal = 1e-12;  // the batch plan's joint goal is exact, a replan's is not
  IncrementalPlanner planner(o);
  const Plan first = planner.plan(rr_scene());
  ASSERT_TRUE(first.success()) << failures(first);
  const Plan re = planner.set_goal(far_goal());
  EXPECT_FALSE(re.success());
  EXPECT_TRUE(mentions(re.validation, "goal error")) << failures(re);
}

TEST(IncrementalPlannerOptions, Isam2Options) {
  IncrementalPlanner by_default;
  ASSERT_TRUE(by_default.plan(rr_scene()).success());
  ASSERT_TRUE(by_default.set_goal(far_goal()).success());
  ASSERT_GT(by_default.last_stats().full_reeliminations, 0);
  IncrementalPlannerOptions o;
  o.isam2.full_reelimination_fraction = 1.0;  // never re-eliminate the whole tree
  IncrementalPlanner planner(o);
  ASSERT_TRUE(planner.plan(rr_scene()).success());
  const Plan re = planner.set_goal(far_goal());
  ASSERT_TRUE(re.success()) << failures(re);
  EXPECT_EQ(planner.last_stats().full_reeliminations, 0);
  EXPECT_GT(planner.last_stats().cliques_reeliminated, 0);
}

TEST(IncrementalPlannerOptions, MaxUpdates) {
  IncrementalPlanner by_default;
  ASSERT_TRUE(by_default.plan(rr_scene()).success());
  ASSERT_TRUE(by_default.set_goal(far_goal()).success());
  ASSERT_GT(by_default.last_stats().updates, 2);
  IncrementalPlannerOptions o;
  o.max_updates = 2;
  IncrementalPlanner planner(o);
  ASSERT_TRUE(planner.plan(rr_scene()).success());
  const Plan re = planner.set_goal(far_goal());
  EXPECT_EQ(re.stats.status, PlanStatus::kMaxUpdates);
  EXPECT_EQ(planner.last_stats().updates, 2);
  // Stopped short, the reason names what still fails in the user's terms.
  EXPECT_NE(re.stats.reason.find("the worst violation: "), std::string::npos) << re.stats.reason;
  EXPECT_NE(re.stats.reason.find("t = "), std::string::npos) << re.stats.reason;
  EXPECT_EQ(re.stats.reason.find("Factor"), std::string::npos) << re.stats.reason;
}

TEST(IncrementalPlannerOptions, MaxRounds) {
  IncrementalPlannerOptions o;
  o.stop_at_first_valid = false;
  IncrementalPlanner rounds(o);
  ASSERT_TRUE(rounds.plan(rr_scene()).success());
  ASSERT_EQ(rounds.set_goal(far_goal()).stats.status, PlanStatus::kConverged);
  ASSERT_GE(rounds.last_stats().rounds, 1) << "the change needs a multiplier round";
  o.max_rounds = 0;
  IncrementalPlanner planner(o);
  ASSERT_TRUE(planner.plan(rr_scene()).success());
  const Plan re = planner.set_goal(far_goal());
  EXPECT_EQ(re.stats.status, PlanStatus::kMaxRounds);
  EXPECT_EQ(planner.last_stats().rounds, 0);
}

TEST(IncrementalPlannerOptions, StopAtFirstValid) {
  IncrementalPlanner first_valid;
  ASSERT_TRUE(first_valid.plan(rr_scene()).success());
  ASSERT_TRUE(first_valid.set_goal(far_goal()).success());
  IncrementalPlannerOptions o;
  o.stop_at_first_valid = false;
  IncrementalPlanner converged(o);
  ASSERT_TRUE(converged.plan(rr_scene()).success());
  const Plan re = converged.set_goal(far_goal());
  ASSERT_TRUE(re.success()) << failures(re);
  EXPECT_GT(converged.last_stats().updates, first_valid.last_stats().updates);
  EXPECT_GT(converged.last_stats().rounds, first_valid.last_stats().rounds);
}

TEST(IncrementalPlannerOptions, SettleFirstPlan) {
  const Problem p = rr_scene();
  IncrementalPlanner settled;
  ASSERT_TRUE(settled.plan(p).success());
  ASSERT_GT(settled.last_stats().updates, 0) << "settling is a replan of the unchanged problem";
  IncrementalPlannerOptions o;
  o.settle_first_plan = false;
  IncrementalPlanner planner(o);
  const Plan first = planner.plan(p);
  ASSERT_TRUE(first.success()) << failures(first);
  EXPECT_EQ(planner.last_stats().updates, 0);
  const Plan batch = BatchPlanner().plan(p);
  EXPECT_EQ(max_abs(first.q - batch.q), 0.0);
  EXPECT_EQ(first.stats.iterations, batch.stats.iterations);
}

// The penalty schedule of the multiplier rounds (converged replans): the RR reach's horizon
// stretched to 4 s takes two rounds, the second of which grows μ by default.
struct HorizonReplan {
  double before = 0, after = 0;
  int rounds = 0;
  explicit HorizonReplan(IncrementalPlannerOptions o) {
    o.stop_at_first_valid = false;
    IncrementalPlanner planner(o);
    EXPECT_TRUE(planner.plan(rr_scene()).success());
    before = planner.last_stats().penalty;
    const Plan re = planner.set_horizon(4.0);
    EXPECT_TRUE(re.success()) << failures(re);
    after = planner.last_stats().penalty;
    rounds = planner.last_stats().rounds;
  }
};

TEST(IncrementalPlannerOptions, MultiplierRoundsGrowThePenaltyByPenaltyGrowth) {
  const HorizonReplan by_default{IncrementalPlannerOptions()};
  ASSERT_GT(by_default.after, by_default.before);
  IncrementalPlannerOptions o;
  o.batch.augmented_lagrangian.penalty_growth = 3;
  const HorizonReplan r(o);
  ASSERT_GE(r.rounds, 2);
  const double k = std::log(r.after / r.before) / std::log(3.0);  // μ grew by 3^k
  EXPECT_GE(k, 1 - 1e-9);
  EXPECT_NEAR(k, std::round(k), 1e-9);
}

TEST(IncrementalPlannerOptions, MultiplierRoundsKeepThePenaltyWhenTheDecreaseSuffices) {
  const HorizonReplan by_default{IncrementalPlannerOptions()};
  ASSERT_GT(by_default.after, by_default.before);
  IncrementalPlannerOptions o;
  o.batch.augmented_lagrangian.required_decrease = 10;  // any violation is decrease enough
  const HorizonReplan r(o);
  ASSERT_GE(r.rounds, 2);
  EXPECT_EQ(r.after, r.before);
}

TEST(IncrementalPlannerOptions, MultiplierRoundsCapThePenaltyAtMaxPenalty) {
  IncrementalPlannerOptions o;
  o.batch.augmented_lagrangian.max_penalty = 500;
  const HorizonReplan r(o);
  ASSERT_GE(r.rounds, 2);
  ASSERT_GT(r.before * o.batch.augmented_lagrangian.penalty_growth, 500) << "a growth overshoots";
  EXPECT_EQ(r.after, 500);
}

// The carried first plan's μ is at least the initial penalty.
TEST(IncrementalPlannerOptions, CarriedPenaltyIsAtLeastTheInitialPenalty) {
  IncrementalPlanner by_default;
  ASSERT_TRUE(by_default.plan(rr_scene()).success());
  ASSERT_LT(by_default.last_stats().penalty, 5e3);
  IncrementalPlannerOptions o;
  o.batch.augmented_lagrangian.initial_penalty = 5e3;
  IncrementalPlanner planner(o);
  ASSERT_TRUE(planner.plan(rr_scene()).success());
  EXPECT_GE(planner.last_stats().penalty, 5e3);
}

// The stopping rule converges the replan's constraints to the outer loop's tolerance.
TEST(IncrementalPlannerOptions, ReplansMeetTheConstraintTolerance) {
  IncrementalPlannerOptions o;
  o.stop_at_first_valid = false;
  {
    IncrementalPlanner planner(o);
    ASSERT_TRUE(planner.plan(rr_scene()).success());
    ASSERT_GT(planner.set_goal(far_goal()).stats.max_constraint_violation, 1e-5);
  }
  o.batch.outer_loop.constraint_tolerance = 1e-5;
  IncrementalPlanner planner(o);
  ASSERT_TRUE(planner.plan(rr_scene()).success());
  const Plan re = planner.set_goal(far_goal());
  ASSERT_TRUE(re.success()) << failures(re);
  EXPECT_LT(re.stats.max_constraint_violation, 1e-5);
}

// ------------------------------------------------------------------------------------------
// ReplannerOptions.

Problem with_goal(Problem p, const Eigen::Vector2d& q) {
  p.goal.q = q;
  return p;
}

TEST(ReplannerOptions, MaxIncrementalGoalChange) {
  const Problem p = rr_scene();
  {
    Replanner by_default;
    ASSERT_TRUE(by_default.plan(p, true).success());
    ASSERT_TRUE(by_default.plan(with_goal(p, {1.05, 0.2}), true).success());
    ASSERT_EQ(by_default.last_report().method, "incremental");
  }
  ReplannerOptions o;
  o.max_incremental_goal_change = 0.1;
  Replanner replanner(o);
  ASSERT_TRUE(replanner.plan(p, true).success());
  const Plan far = replanner.plan(with_goal(p, {1.05, 0.2}), true);  // 0.2 rad away
  ASSERT_TRUE(far.success()) << failures(far);
  EXPECT_EQ(replanner.last_report().method, "batch");
  EXPECT_FALSE(replanner.last_report().incremental);
  const Plan near = replanner.plan(with_goal(p, {1.0, 0.25}), true);  // 0.05 rad away
  ASSERT_TRUE(near.success()) << failures(near);
  EXPECT_EQ(replanner.last_report().method, "incremental");
}

TEST(ReplannerOptions, UseIncremental) {
  const Problem p = rr_scene();
  ReplannerOptions o;
  o.use_incremental = false;
  Replanner replanner(o);
  ASSERT_TRUE(replanner.plan(p, true).success());
  const Plan goal = replanner.plan(with_goal(p, {1.05, 0.2}), true);
  ASSERT_TRUE(goal.success()) << failures(goal);
  EXPECT_EQ(replanner.last_report().method, "batch");
  Problem moved = with_goal(p, {1.05, 0.2});
  moved.start_q += Eigen::Vector2d(0.05, 0.0);  // same goal, new start: warm-started
  const Plan warm = replanner.plan(moved, false);
  ASSERT_TRUE(warm.success()) << failures(warm);
  EXPECT_EQ(replanner.last_report().method, "warm-start");
  EXPECT_FALSE(replanner.last_report().incremental);
  EXPECT_FALSE(replanner.incremental().has_plan());
}

// Replans that cannot succeed (no ISAM2 update allowed) and what answers them.
ReplannerOptions failing_replans() {
  ReplannerOptions o;
  o.incremental.max_updates = 0;
  return o;
}

TEST(ReplannerOptions, IncrementalOptionsReachTheIncrementalPlanner) {
  const Problem p = rr_scene();
  ReplannerOptions o = failing_replans();
  o.fallback = false;
  o.retry_from_scratch = false;
  Replanner replanner(o);
  ASSERT_TRUE(replanner.plan(p, true).success());
  const Plan re = replanner.plan(with_goal(p, {1.05, 0.2}), true);
  EXPECT_EQ(re.stats.status, PlanStatus::kMaxUpdates);
  EXPECT_EQ(replanner.last_report().statistics.updates, 0);
  // ... and the batch solves (the first plan of use_incremental = false).
  ReplannerOptions b;
  b.use_incremental = false;
  b.incremental.batch.validation.final_velocity = -1;
  Replanner batch_only(b);
  EXPECT_TRUE(mentions(batch_only.plan(p, true).validation, "final velocity"));
}

TEST(ReplannerOptions, Fallback) {
  const Problem p = rr_scene();
  {
    Replanner by_default(failing_replans());
    ASSERT_TRUE(by_default.plan(p, true).success());
    ASSERT_TRUE(by_default.plan(with_goal(p, {1.05, 0.2}), true).success());
    ASSERT_TRUE(by_default.last_report().fell_back);
    EXPECT_FALSE(by_default.last_report().retried_from_scratch);  // the fallback validated
  }
  ReplannerOptions o = failing_replans();
  o.fallback = false;
  Replanner replanner(o);
  ASSERT_TRUE(replanner.plan(p, true).success());
  const Plan re = replanner.plan(with_goal(p, {1.05, 0.2}), true);
  EXPECT_TRUE(replanner.last_report().incremental);
  EXPECT_FALSE(replanner.last_report().fell_back);
  // The retry from scratch answers instead.
  EXPECT_TRUE(re.success()) << failures(re);
  EXPECT_EQ(replanner.last_report().method, "batch after incremental");
  EXPECT_TRUE(replanner.last_report().retried_from_scratch);
}

TEST(ReplannerOptions, RetryFromScratch) {
  const Problem p = rr_scene();
  ReplannerOptions o = failing_replans();
  o.fallback = false;
  o.retry_from_scratch = false;
  Replanner replanner(o);
  ASSERT_TRUE(replanner.plan(p, true).success());
  const Plan re = replanner.plan(with_goal(p, {1.05, 0.2}), true);
  EXPECT_FALSE(re.success());
  EXPECT_EQ(replanner.last_report().method, "incremental");
  EXPECT_FALSE(replanner.last_report().retried_from_scratch);
}

}  // namespace
}  // namespace kinograph::planning

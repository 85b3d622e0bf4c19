// Tests of the DFG builder: structure of a step, initial values from RNEA, and solving a
// single-step DFG with Levenberg–Marquardt for inverse and forward dynamics.
#include "kinograph/planning/formulation/dfg_builder.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/dynamics/payload.h"
#include "kinograph/graph/factor_graph.h"
#include "kinograph/graph/levenberg_marquardt.h"
#include "kinograph/graph/prior_factor.h"
#include "kinograph/graph/testing/numerical_jacobian.h"
#include "kinograph/graph/values.h"
#include "kinograph/planning/solver/augmented_lagrangian.h"
#include "kinograph/planning/factors/dynamics_factors.h"
#include "kinograph/planning/formulation/planning_graph.h"
#include "kinograph/planning/formulation/initialization.h"
#include "kinograph/planning/problem.h"
#include "test_problems.h"

namespace kinograph::planning {
namespace {

using dynamics::Model;
using graph::Key;

std::string robot(const std::string& rel) {
  return std::string(KINOGRAPH_SOURCE_DIR) + "/robots/" + rel;
}

Model iiwa_with_block() {
  return dynamics::attach_box_payload(Model::from_urdf_file(robot("iiwa14/iiwa14.urdf")),
                                      "iiwa_link_ee_kuka", 2.0, {0.1, 0.1, 0.1},
                                      Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.05)));
}

Eigen::VectorXd uniform(std::mt19937& rng, int n, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

void insert_joints(graph::Values& values, const DfgKeys& k, int step, const Eigen::VectorXd& q,
                   const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
  values.insert(k.q_key(step), q);
  values.insert(k.qd_key(step), qd);
  values.insert(k.qdd_key(step), qdd);
}

graph::LevenbergMarquardtOptions tight() {
  graph::LevenbergMarquardtOptions o;
  o.relative_error_tol = 0;
  o.absolute_error_tol = 1e-24;
  o.max_iterations = 50;
  return o;
}

TEST(DfgBuilder, StepStructure) {
  const Model m = iiwa_with_block();
  const int n = m.nq();
  graph::FactorGraph graph;
  graph::Values values;
  DfgOptions options;
  std::mt19937 rng(3);
  for (int step = 0; step < 3; ++step) {
    insert_joints(values, options.keys, step, uniform(rng, n, 1), uniform(rng, n, 1),
                  uniform(rng, n, 1));
  }
  std::vector<DfgStep> steps;
  for (int step = 0; step < 3; ++step) {
    steps.push_back(add_dfg_dynamics(graph, values, m, step, options));
  }
  EXPECT_EQ(graph.num_factors(), 3u * 4u * n);
  // 3 joint vectors + 3 six-vectors and one scalar per body and step.
  EXPECT_EQ(values.size(), 3 * (3 + 4 * n));
  EXPECT_EQ(values.total_dim(), 3 * (3 * n + 19 * n));
  std::set<size_t> seen;
  for (const DfgStep& s : steps) {
    EXPECT_EQ(s.size(), 4u * n);
    for (size_t f : s.all()) {
      EXPECT_TRUE(seen.insert(f).second) << "factor " << f << " listed twice";
      for (Key k : graph.at(f)->keys()) {
        EXPECT_EQ(k.step(), static_cast<uint32_t>(s.step)) << "factors couple only one step";
      }
    }
  }
  EXPECT_EQ(seen.size(), graph.num_factors());
  // A second call for a step overwrites its values rather than inserting twice.
  dynamics::Data data(m);
  set_dfg_values(values, m, data, 1, Eigen::VectorXd::Zero(n), Eigen::VectorXd::Zero(n),
                 Eigen::VectorXd::Zero(n), options);
  EXPECT_EQ(values.size(), 3 * (3 + 4 * n));
}

TEST(DfgBuilder, TorqueVectorLayout) {
  const Model m = Model::from_urdf_file(robot("acrobot/acrobot.urdf"));
  DfgOptions options;
  options.keys.torque_vector = true;
  graph::FactorGraph graph;
  graph::Values values;
  const Eigen::Vector2d q(0.3, -0.4), qd(1.0, 0.5), qdd(-2.0, 1.0);
  insert_joints(values, options.keys, 5, q, qd, qdd);
  const DfgStep s = add_dfg_dynamics(graph, values, m, 5, options);
  EXPECT_EQ(values.at(Key('T', 0, 5)).size(), 2);
  EXPECT_FALSE(values.contains(Key('T', 1, 5)));
  dynamics::Data data(m);
  const Eigen::VectorXd tau = dynamics::rnea(m, data, q, qd, qdd);
  EXPECT_LT((dfg_torques(values, m, 5, options.keys) - tau).norm(), 1e-12);
  EXPECT_LT(dfg_max_residual(graph, values, s.all()), 1e-12);
}

// The builder's initial values satisfy the DFG (zero residual) and hold rnea's torques; moving
// a joint without re-initialising breaks it, which the residual reports.
TEST(DfgBuilder, InitialValuesHaveZeroResidual) {
  std::mt19937 rng(11);
  for (const Model& m : {Model::from_urdf_file(robot("acrobot/acrobot.urdf")), iiwa_with_block()}) {
    const int n = m.nq();
    DfgOptions options;
    options.external = {{n - 1, uniform(rng, 6, 4.0)}};  // a push on the last body
    graph::FactorGraph graph;
    graph::Values values;
    const Eigen::VectorXd q = uniform(rng, n, 3), qd = uniform(rng, n, 2), qdd = uniform(rng, n, 5);
    insert_joints(values, options.keys, 0, q, qd, qdd);
    const DfgStep s = add_dfg_dynamics(graph, values, m, 0, options);
    EXPECT_LT(dfg_max_residual(graph, values, s.all()), 1e-10) << m.name;
    dynamics::Data data(m);
    const Eigen::VectorXd tau = dynamics::rnea(m, data, q, qd, qdd, options.external);
    EXPECT_LT((dfg_torques(values, m, 0) - tau).cwiseAbs().maxCoeff(), 1e-10) << m.name;

    // (Joint 1, not 0: the iiwa's first axis is vertical, and turning it changes nothing in the
    // body frames.)
    values.at(options.keys.q_key(0))[1] += 0.1;
    EXPECT_GT(dfg_max_residual(graph, values, s.all()), 1e-3) << m.name;
  }
}

// Inverse dynamics by optimisation: with q, q̇, q̈ fixed and V, V̇, F, τ started at zero, LM on
// the single-step DFG converges to rnea's τ.
TEST(DfgBuilder, SingleStepSolveRecoversRnea) {
  std::mt19937 rng(5);
  for (const Model& m : {Model::from_urdf_file(robot("acrobot/acrobot.urdf")), iiwa_with_block()}) {
    const int n = m.nq();
    DfgOptions options;
    options.sigma = 1.0;
    graph::FactorGraph graph;
    graph::Values values;
    const Eigen::VectorXd q = uniform(rng, n, 3), qd = uniform(rng, n, 2), qdd = uniform(rng, n, 5);
    insert_joints(values, options.keys, 0, q, qd, qdd);
    const DfgStep s = add_dfg_dynamics(graph, values, m, 0, options);
    for (Key k : {options.keys.q_key(0), options.keys.qd_key(0), options.keys.qdd_key(0)}) {
      values.set_fixed(k);
    }
    for (int i = 0; i < values.size(); ++i) {
      if (!values.is_fixed_slot(i)) values.at_slot(i).setZero();
    }
    ASSERT_GT(dfg_max_residual(graph, values, s.all()), 1.0);

    graph::LevenbergMarquardt lm(tight());
    const graph::OptimizationResult r = lm.optimize(graph, values);
    EXPECT_LT(r.final_error, 1e-18)
        << m.name << " " << graph::to_string(r.status) << " " << r.reason;
    dynamics::Data data(m);
    const Eigen::VectorXd tau = dynamics::rnea(m, data, q, qd, qdd);
    EXPECT_LT((dfg_torques(values, m, 0) - tau).cwiseAbs().maxCoeff(), 1e-7) << m.name;
    EXPECT_LT(dfg_max_residual(graph, values, s.all()), 1e-8) << m.name;
  }
}

// Forward dynamics by optimisation: with q, q̇ and τ pinned by priors and q̈ free (started at
// zero), LM on the single-step DFG converges to dynamics::forward_dynamics' q̈. This exercises
// the factors' Jacobians with respect to the joint variables inside a real solve.
TEST(DfgBuilder, SingleStepSolveRecoversForwardDynamics) {
  std::mt19937 rng(8);
  for (const Model& m : {Model::from_urdf_file(robot("acrobot/acrobot.urdf")), iiwa_with_block()}) {
    const int n = m.nq();
    DfgOptions options;
    options.sigma = 1.0;
    options.keys.torque_vector = true;
    graph::FactorGraph graph;
    graph::Values values;
    const Eigen::VectorXd q = uniform(rng, n, 2), qd = uniform(rng, n, 1),
                          tau = uniform(rng, n, 10);
    dynamics::Data data(m);
    const Eigen::VectorXd qdd = dynamics::forward_dynamics(m, data, q, qd, tau);

    insert_joints(values, options.keys, 0, q, qd, Eigen::VectorXd::Zero(n));
    add_dfg_dynamics(graph, values, m, 0, options);
    values.set_fixed(options.keys.q_key(0));
    values.set_fixed(options.keys.qd_key(0));
    graph.emplace<graph::PriorFactor>(options.keys.torque_key(0, 0), tau,
                                      graph::isotropic(n, 1e-6));

    graph::LevenbergMarquardt lm(tight());
    const graph::OptimizationResult r = lm.optimize(graph, values);
    EXPECT_LT(r.final_error, 1e-12)
        << m.name << " " << graph::to_string(r.status) << " " << r.reason;
    EXPECT_LT((values.at(options.keys.qdd_key(0)) - qdd).cwiseAbs().maxCoeff(), 1e-6)
        << m.name << "\n"
        << values.at(options.keys.qdd_key(0)).transpose() << "\n"
        << qdd.transpose();
  }
}

// The constrained form: every DFG equation as equality rows, and the torque rows on τ. At
// RNEA-initialised values the equations hold (no violation) and the torque rows read the same z
// as the condensed DynamicsStepFactor; Jacobians (through the augmented-Lagrangian residual,
// with multipliers and μ set) match central differences.
TEST(DfgBuilder, ConstraintStepMatchesCondensedRows) {
  std::mt19937 rng(21);
  for (bool torque_vector : {false, true}) {
    auto model = testing::acrobot_model();
    const int n = model->nq();
    DfgOptions options;
    options.keys.torque_vector = torque_vector;
    options.constraint_scale = 2.0;
    DynamicsStepOptions rows;
    rows.min_torque = 0.5;
    graph::FactorGraph graph;
    graph::Values values;
    const Eigen::VectorXd q = uniform(rng, n, 3), qd = uniform(rng, n, 2), qdd = uniform(rng, n, 5);
    insert_joints(values, options.keys, 4, q, qd, qdd);
    dynamics::Data data(*model);
    const DfgConstraintStep s = add_dfg_constraints(graph, values, *model, data, 4, rows, options);
    ASSERT_EQ(s.factors.size(), 4u * n + 1);  // + the torque rows
    ASSERT_EQ(s.indices.size(), s.factors.size());
    for (size_t i = 0; i < s.factors.size(); ++i) {
      EXPECT_EQ(graph.at(s.indices[i]).get(), s.factors[i].get());
      if (i < 4u * n) {
        EXPECT_LT(s.factors[i]->violation(values), 1e-10) << s.factors[i]->name();
      }
    }
    // Same rows and values as the condensed factor at the same state.
    auto workspace = std::make_shared<DynamicsWorkspace>(model);
    const DynamicsStepFactor condensed(4, model, workspace, rows);
    Eigen::VectorXd z_dfg, z_condensed;
    s.factors.back()->values_at(values, z_dfg);
    graph::Values joint_values;
    insert_joints(joint_values, options.keys, 4, q, qd, qdd);
    condensed.values_at(joint_values, z_condensed);
    ASSERT_EQ(z_dfg.size(), z_condensed.size());
    EXPECT_LT((z_dfg - z_condensed).cwiseAbs().maxCoeff(), 1e-10);
    ASSERT_EQ(s.factors.back()->rows().size(), condensed.rows().size());
    for (size_t r = 0; r < condensed.rows().size(); ++r) {
      EXPECT_EQ(s.factors.back()->rows()[r].kind, condensed.rows()[r].kind);
      EXPECT_EQ(s.factors.back()->rows()[r].lower, condensed.rows()[r].lower);
      EXPECT_EQ(s.factors.back()->rows()[r].upper, condensed.rows()[r].upper);
    }

    // Jacobians of the augmented-Lagrangian residuals away from RNEA's values.
    for (int i = 0; i < values.size(); ++i) {
      if (values.key(i).kind() != 'q' && values.key(i).kind() != 'v' &&
          values.key(i).kind() != 'a') {
        values.at_slot(i) += uniform(rng, values.dim(i), 0.5);
      }
    }
    for (const auto& f : s.factors) {
      auto m = std::make_shared<Multipliers>(f->residual_dim(), 30.0);
      m->lower = uniform(rng, f->residual_dim(), 1.0);
      m->upper = uniform(rng, f->residual_dim(), 1.0).cwiseAbs();
      f->bind(m);
      const auto check = graph::testing::check_jacobians(*f, values);
      EXPECT_TRUE(check.ok) << f->name() << "\n" << check.report();
    }
  }
}

// The two formulations pose the same single-step problem: the Acrobot at a fixed (q, q̇) with
// q̈ pulled towards a target by a soft prior, subject to the shoulder being unactuated
// (τ₁ = 0) and the elbow's ±8 N·m. The augmented-Lagrangian loop on the DFG and on the condensed
// factor reach the same q̈ and torques.
TEST(DfgBuilder, ConstrainedSingleStepAgreesWithCondensed) {
  auto model = testing::acrobot_model();
  const int n = model->nq();
  const Eigen::Vector2d q(0.4, -0.9), qd(1.5, -2.0), target(6.0, -9.0);
  DynamicsStepOptions rows;
  struct Result {
    Eigen::VectorXd qdd, tau;
  };
  auto solve = [&](bool dfg) {
    DfgOptions options;
    graph::FactorGraph graph;
    graph::Values values;
    insert_joints(values, options.keys, 0, q, qd, Eigen::VectorXd::Zero(n));
    values.set_fixed(options.keys.q_key(0));
    values.set_fixed(options.keys.qd_key(0));
    graph.emplace<graph::PriorFactor>(options.keys.qdd_key(0), target);
    std::vector<std::shared_ptr<ConstrainedFactor>> constraints;
    auto workspace = std::make_shared<DynamicsWorkspace>(model);
    if (dfg) {
      constraints =
          add_dfg_constraints(graph, values, *model, workspace->local(), 0, rows, options).factors;
    } else {
      auto f = std::make_shared<DynamicsStepFactor>(0, model, workspace, rows);
      graph.add(f);
      constraints.push_back(f);
    }
    std::vector<FactorEntry> entries;
    for (size_t i = 0; i < constraints.size(); ++i) {
      entries.push_back(make_entry(constraints[i], {FactorRole::kDynamics, 0, static_cast<int>(i)}));
    }
    std::vector<const FactorEntry*> tracked;
    for (const FactorEntry& e : entries) {
      if (e.constrained->has_constraints()) tracked.push_back(&e);
    }
    ConstraintState state;
    AugmentedLagrangian al(tracked, state);
    graph::LevenbergMarquardtOptions lm_options;
    lm_options.relative_error_tol = 1e-10;
    graph::LevenbergMarquardt lm(lm_options);
    for (int outer = 0; outer < 30; ++outer) {
      lm.optimize(graph, values);
      if (al.update(values) < 1e-9) break;
    }
    Result r;
    r.qdd = values.at(options.keys.qdd_key(0));
    dynamics::Data data(*model);
    r.tau = dynamics::rnea(*model, data, q, qd, r.qdd);
    if (dfg) {
      EXPECT_LT((dfg_torques(values, *model, 0) - r.tau).cwiseAbs().maxCoeff(), 1e-6);
    }
    return r;
  };
  const Result condensed = solve(false), dfg = solve(true);
  EXPECT_NEAR(condensed.tau[0], 0.0, 1e-6);
  EXPECT_LE(std::abs(condensed.tau[1]), 8.0 + 1e-6);
  EXPECT_GT(std::abs(condensed.tau[1]), 7.9) << "the elbow bound should be active";
  EXPECT_LT((dfg.qdd - condensed.qdd).cwiseAbs().maxCoeff(), 1e-5)
      << dfg.qdd.transpose() << " vs " << condensed.qdd.transpose();
  EXPECT_LT((dfg.tau - condensed.tau).cwiseAbs().maxCoeff(), 1e-5);
}

// Whole trajectories: the planner's condensed graph (build_graph) and the same graph with each
// step's DynamicsStepFactor replaced by the DFG (add_dfg_constraints), solved by the same
// augmented-Lagrangian loop from the same straight-line start, reach the same plan. The
// minimum-torque term makes the optimum depend on the torques, so the DFG's τ must be right.
TEST(DfgBuilder, WholeTrajectoryAgreesWithCondensed) {
  Problem problem;
  problem.name = "rr_dfg_vs_condensed";
  problem.model = std::make_shared<const Model>(Model::from_urdf_file(robot("rr/rr.urdf")));
  problem.horizon = 1.5;
  problem.steps = 12;
  problem.start_q = Eigen::Vector2d(0.2, -0.3);
  problem.start_qd = Eigen::Vector2d::Zero();
  problem.goal.q = Eigen::Vector2d(1.0, 0.6);
  problem.objectives.min_torque = 0.01;
  const GraphOptions graph_options;
  const Model& model = *problem.model;

  auto solve = [&](bool dfg) {
    const Trajectory init = straight_line(problem, problem.goal.q);
    PlanningGraph pg = build_graph(problem, init, graph_options);
    if (dfg) {
      const auto steps = use_dfg_dynamics(pg, problem, graph_options);
      EXPECT_EQ(steps.size(), static_cast<size_t>(problem.steps + 1));
      for (size_t i = 0; i < pg.graph.size(); ++i) {
        EXPECT_EQ(dynamic_cast<const DynamicsStepFactor*>(pg.graph[i].get()), nullptr);
      }
      // 4·nq equation factors + the torque rows per step, all constraints.
      size_t dfg_constraints = 0;
      for (const FactorEntry* e : pg.constraints(false)) {
        const ConstrainedFactor* c = e->constrained.get();
        dfg_constraints += dynamic_cast<const DfgConstraintFactor*>(c) != nullptr ||
                           dynamic_cast<const DfgTorqueRowsFactor*>(c) != nullptr;
      }
      EXPECT_EQ(dfg_constraints, (problem.steps + 1) * (4u * model.nq() + 1));
    }
    ConstraintState state;
    AugmentedLagrangian al(pg.constraints(false), state);
    graph::LevenbergMarquardtOptions lm_options;
    lm_options.relative_error_tol = 1e-12;
    lm_options.max_iterations = 100;
    graph::LevenbergMarquardt lm(lm_options);
    double violation = 1;
    for (int outer = 0; outer < 30 && violation > 1e-9; ++outer) {
      lm.optimize(pg.graph, pg.values);
      violation = al.update(pg.values);
    }
    EXPECT_LT(violation, 1e-7) << (dfg ? "dfg" : "condensed");
    if (dfg) {  // the DFG's torques are RNEA's at the solution
      dynamics::Data data(model);
      for (int k = 0; k <= problem.steps; ++k) {
        const Eigen::VectorXd tau =
            dynamics::rnea(model, data, pg.values.at(Key('q', 0, k)), pg.values.at(Key('v', 0, k)),
                           pg.values.at(Key('a', 0, k)));
        EXPECT_LT((dfg_torques(pg.values, model, k) - tau).cwiseAbs().maxCoeff(), 1e-5) << k;
      }
    }
    return read_trajectory(pg.values, problem.steps, model.nq());
  };
  const Trajectory condensed = solve(false), dfg = solve(true);
  EXPECT_LT((dfg.q - condensed.q).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_LT((dfg.qd - condensed.qd).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_LT((dfg.qdd - condensed.qdd).cwiseAbs().maxCoeff(), 1e-4);
  // And the plan is not simply the initial straight line.
  const Trajectory init = straight_line(problem, problem.goal.q);
  EXPECT_GT((condensed.qdd - init.qdd).cwiseAbs().maxCoeff(), 1e-3);
}

TEST(DfgBuilder, RejectsExternalWrenchOnMissingBody) {
  const Model m = Model::from_urdf_file(robot("rr/rr.urdf"));
  graph::FactorGraph graph;
  DfgOptions options;
  options.external = {{2, dynamics::Vector6::Zero()}};
  EXPECT_THROW(add_dfg_factors(graph, m, 0, options), std::invalid_argument);
}

}  // namespace
}  // namespace kinograph::planning

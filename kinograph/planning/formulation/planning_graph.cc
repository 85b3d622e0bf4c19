#include "kinograph/planning/formulation/planning_graph.h"

#include <cmath>
#include <stdexcept>

#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/planning/factors/dynamics_factors.h"
#include "kinograph/planning/factors/pose_factors.h"
#include "kinograph/planning/factors/trajectory_factors.h"

namespace kinograph::planning {

PlanningGraph build_graph(const Problem& problem, const Trajectory& init,
                          const GraphOptions& options) {
  if (!problem.model) throw std::invalid_argument("problem has no model");
  const auto& model = problem.model;
  const int n = model->nq(), N = problem.steps;
  const double dt = problem.dt();
  const Objectives& obj = problem.objectives;
  if (init.q.rows() != N + 1 || init.q.cols() != n || init.qd.rows() != N + 1 ||
      init.qdd.rows() != N + 1) {
    throw std::invalid_argument("initial trajectory has the wrong shape");
  }
  PlanningGraph pg;
  pg.steps = N;
  pg.nq = n;
  pg.dynamics_workspace = std::make_shared<dynamics::Data>(*model);
  auto add_constraint = [&pg](std::shared_ptr<ConstrainedFactor> f) {
    pg.graph.add(f);
    if (f->has_constraints()) pg.constraints.push_back(std::move(f));
  };

  for (int k = 0; k <= N; ++k) {
    pg.values.insert(q_key(k), init.q.row(k).transpose());
    pg.values.insert(v_key(k), init.qd.row(k).transpose());
    pg.values.insert(a_key(k), init.qdd.row(k).transpose());
  }
  // Start: exact by fixing the variables.
  pg.values.update(q_key(0), problem.start_q);
  pg.values.update(v_key(0),
                   problem.start_qd.size() == n ? problem.start_qd : Eigen::VectorXd::Zero(n));
  pg.values.set_fixed(q_key(0));
  pg.values.set_fixed(v_key(0));
  // Goal at rest.
  pg.values.update(v_key(N), Eigen::VectorXd::Zero(n));
  pg.values.update(a_key(N), Eigen::VectorXd::Zero(n));
  pg.values.set_fixed(v_key(N));
  pg.values.set_fixed(a_key(N));
  if (problem.goal.kind == Goal::Kind::kJoint) {
    if (problem.goal.q.size() != n) throw std::invalid_argument("joint goal has the wrong size");
    pg.values.update(q_key(N), problem.goal.q);
    pg.values.set_fixed(q_key(N));
  } else {
    const PoseParts parts = problem.goal.position_only ? PoseParts::kPosition : PoseParts::kFull;
    add_constraint(std::make_shared<PoseFactor>(N, model, pg.dynamics_workspace, problem.goal.frame,
                                                problem.goal.pose, parts, options.pose_scale));
  }

  // Between states: GP prior (soft) and collocation (must hold).
  for (int k = 0; k < N; ++k) {
    pg.graph.emplace<GpPriorFactor>(k, n, dt, obj.qc);
    add_constraint(std::make_shared<CollocationFactor>(k, n, dt, options.collocation_scale));
  }

  // Per-state limits and dynamics.
  std::vector<StateLimitFactor::Limit> limits;
  for (int j = 0; j < n; ++j) {
    const dynamics::JointLimits& l = model->bodies[j].limits;
    const double eps = obj.limit_epsilon;
    if (std::isfinite(l.lower) || std::isfinite(l.upper))
      limits.push_back({0, j, l.lower + eps, l.upper - eps});
    if (std::isfinite(l.velocity)) limits.push_back({1, j, -l.velocity + eps, l.velocity - eps});
    if (std::isfinite(l.acceleration))
      limits.push_back({2, j, -l.acceleration + eps, l.acceleration - eps});
  }
  DynamicsStepOptions dyn;
  dyn.limit_epsilon = obj.limit_epsilon;
  dyn.min_torque = obj.min_torque;
  dyn.torque_scale = options.torque_scale;
  const bool has_dynamics = !DynamicsStepFactor::rows_for(*model, dyn).empty();
  for (int k = 0; k <= N; ++k) {
    if (!limits.empty()) {
      auto f = std::make_shared<StateLimitFactor>(k, n, limits, options.limit_scale);
      add_constraint(f);
    }
    if (has_dynamics) {
      add_constraint(std::make_shared<DynamicsStepFactor>(k, model, pg.dynamics_workspace, dyn));
    }
  }
  // Collision at every state and at interpolated states between them.
  if (!problem.obstacles.empty() && !model->collision.empty()) {
    pg.collision = std::make_shared<CollisionContext>(
        model, problem.obstacles, obj.collision_epsilon + options.collision_query_margin);
    if (pg.collision->num_pairs > 0) {
      const int sub = std::max(0, obj.collision_substeps);
      for (int k = 0; k <= N; ++k) {
        if (k > 0) {  // the start state is fixed; its clearance is checked before planning
          add_constraint(std::make_shared<CollisionFactor>(k, 0.0, dt, obj.collision_epsilon,
                                                           options.collision_scale, pg.collision));
        }
        if (k == N) break;
        for (int i = 1; i <= sub; ++i) {
          add_constraint(std::make_shared<CollisionFactor>(k, static_cast<double>(i) / (sub + 1),
                                                           dt, obj.collision_epsilon,
                                                           options.collision_scale, pg.collision));
        }
      }
    }
  }

  // Task constraints on every free state.
  for (const TaskConstraint& task : problem.task_constraints) {
    const PoseParts parts = task.orientation_only ? PoseParts::kOrientation : PoseParts::kFull;
    for (int k = 1; k <= N; ++k) {
      add_constraint(std::make_shared<PoseFactor>(k, model, pg.dynamics_workspace, task.frame,
                                                  task.target, parts, options.pose_scale));
    }
  }
  return pg;
}

Trajectory read_trajectory(const graph::Values& values, int steps, int nq) {
  Trajectory tr;
  tr.q.resize(steps + 1, nq);
  tr.qd.resize(steps + 1, nq);
  tr.qdd.resize(steps + 1, nq);
  for (int k = 0; k <= steps; ++k) {
    tr.q.row(k) = values.at(q_key(k)).transpose();
    tr.qd.row(k) = values.at(v_key(k)).transpose();
    tr.qdd.row(k) = values.at(a_key(k)).transpose();
  }
  return tr;
}

Plan plan_from_trajectory(const Problem& problem, const Trajectory& trajectory) {
  const int n = problem.model->nq(), N = problem.steps;
  Plan plan;
  plan.q = trajectory.q;
  plan.qd = trajectory.qd;
  plan.qdd = trajectory.qdd;
  plan.tau.resize(N + 1, n);
  plan.t.resize(N + 1);
  dynamics::Data data(*problem.model);
  for (int k = 0; k <= N; ++k) {
    plan.t[k] = problem.dt() * k;
    plan.tau.row(k) =
        dynamics::rnea(*problem.model, data, trajectory.q.row(k).transpose(),
                       trajectory.qd.row(k).transpose(), trajectory.qdd.row(k).transpose())
            .transpose();
  }
  return plan;
}

}  // namespace kinograph::planning

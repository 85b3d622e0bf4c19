#include "kinograph/planning/formulation/planning_graph.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>

#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/planning/clearance_world.h"
#include "kinograph/planning/factors/dynamics_factors.h"
#include "kinograph/planning/factors/interval_factors.h"
#include "kinograph/planning/factors/pose_factors.h"
#include "kinograph/planning/factors/state_target_factor.h"
#include "kinograph/planning/factors/trajectory_factors.h"

namespace kinograph::planning {
namespace {

// Weight of the start prior w·(x_0 − start): a linear soft term outside the augmented
// Lagrangian (it does not stiffen as μ grows) that holds the start to about force/w², far
// inside the validator's start threshold.
constexpr double kStartPriorWeight = 1e5;
// Scale of the joint goal's equality rows (rad).
constexpr double kJointGoalScale = 1e-2;

std::vector<StateLimitFactor::Limit> joint_limits(const dynamics::Model& model, double eps) {
  std::vector<StateLimitFactor::Limit> limits;
  for (int j = 0; j < model.nq(); ++j) {
    const dynamics::JointLimits& l = model.bodies[j].limits;
    if (std::isfinite(l.lower) || std::isfinite(l.upper))
      limits.push_back({0, j, l.lower + eps, l.upper - eps});
    if (std::isfinite(l.velocity)) limits.push_back({1, j, -l.velocity + eps, l.velocity - eps});
    if (std::isfinite(l.acceleration))
      limits.push_back({2, j, -l.acceleration + eps, l.acceleration - eps});
  }
  return limits;
}

// Limits and condensed dynamics of states first..N, state by state.
std::vector<FactorEntry> state_entries(const Problem& problem,
                                       const std::shared_ptr<DynamicsWorkspace>& workspace,
                                       const GraphOptions& options, int first) {
  std::vector<FactorEntry> out;
  const auto& model = problem.model;
  const Objectives& obj = problem.objectives;
  const std::vector<StateLimitFactor::Limit> limits = joint_limits(*model, obj.limit_epsilon);
  DynamicsStepOptions dyn;
  dyn.limit_epsilon = obj.limit_epsilon;
  dyn.min_torque = obj.min_torque;
  dyn.torque_scale = options.torque_scale;
  const bool has_dynamics = !DynamicsStepFactor::rows_for(*model, dyn).empty();
  for (int k = first; k <= problem.steps; ++k) {
    if (!limits.empty()) {
      out.push_back(make_entry(
          std::make_shared<StateLimitFactor>(k, model->nq(), limits, options.limit_scale),
          {FactorRole::kLimits, k}));
    }
    if (has_dynamics) {
      out.push_back(make_entry(std::make_shared<DynamicsStepFactor>(k, model, workspace, dyn),
                               {FactorRole::kDynamics, k}));
    }
  }
  return out;
}

// Task constraints on the free states from `first` on, task by task.
std::vector<FactorEntry> task_entries(const Problem& problem,
                                      const std::shared_ptr<DynamicsWorkspace>& workspace,
                                      const GraphOptions& options, int first) {
  std::vector<FactorEntry> out;
  for (size_t t = 0; t < problem.task_constraints.size(); ++t) {
    const TaskConstraint& task = problem.task_constraints[t];
    const PoseParts parts = task.orientation_only ? PoseParts::kOrientation : PoseParts::kFull;
    for (int k = std::max(first, 1); k <= problem.steps; ++k) {
      out.push_back(make_entry(std::make_shared<PoseFactor>(k, problem.model, workspace,
                                                            task.frame, task.target, parts,
                                                            options.pose_scale),
                               {FactorRole::kTask, k, 0, static_cast<int>(t)}));
    }
  }
  return out;
}

// Variables of every state from `init`; the start fixed, the goal at rest, a joint goal fixed.
graph::Values initial_values(const Problem& problem, const Trajectory& init) {
  const int n = problem.model->nq(), N = problem.steps;
  graph::Values values;
  for (int k = 0; k <= N; ++k) {
    values.insert(q_key(k), init.q.row(k).transpose());
    values.insert(v_key(k), init.qd.row(k).transpose());
    values.insert(a_key(k), init.qdd.row(k).transpose());
  }
  values.update(q_key(0), problem.start_q);
  values.update(v_key(0),
                problem.start_qd.size() == n ? problem.start_qd : Eigen::VectorXd::Zero(n));
  values.set_fixed(q_key(0));
  values.set_fixed(v_key(0));
  values.update(v_key(N), Eigen::VectorXd::Zero(n));
  values.update(a_key(N), Eigen::VectorXd::Zero(n));
  values.set_fixed(v_key(N));
  values.set_fixed(a_key(N));
  if (problem.goal.kind == Goal::Kind::kJoint) {
    if (problem.goal.q.size() != n) throw std::invalid_argument("joint goal has the wrong size");
    values.update(q_key(N), problem.goal.q);
    values.set_fixed(q_key(N));
  }
  return values;
}

}  // namespace

void PlanningGraph::add(FactorEntry entry) {
  if (!entry.anchor) entry.slot = graph.add(entry.factor);
  entries.push_back(std::move(entry));
}

std::vector<const FactorEntry*> PlanningGraph::constraints(bool with_anchors) const {
  std::vector<const FactorEntry*> out;
  for (const FactorEntry& e : entries) {
    if (e.constrained && e.constrained->has_constraints() && (with_anchors || !e.anchor)) {
      out.push_back(&e);
    }
  }
  return out;
}

FactorEntry make_entry(std::shared_ptr<ConstrainedFactor> factor, FactorKey key) {
  FactorEntry e;
  e.factor = factor;
  e.constrained = std::move(factor);
  e.key = key;
  return e;
}

FactorEntry make_soft_entry(graph::FactorPtr soft_factor, FactorKey key) {
  FactorEntry e;
  e.factor = std::move(soft_factor);
  e.key = key;
  return e;
}

std::vector<FactorEntry> timing_entries(const Problem& problem, const GraphOptions& options,
                                        const IntervalRows& rows) {
  std::vector<FactorEntry> out;
  const dynamics::Model& model = *problem.model;
  const int n = model.nq();
  const double dt = problem.dt();
  if (!rows.limits.empty() && static_cast<int>(rows.limits.size()) != problem.steps) {
    throw std::invalid_argument("interval rows: " + std::to_string(rows.limits.size()) +
                                " limit flags for " + std::to_string(problem.steps) +
                                " intervals");
  }
  std::vector<int> cubic;  // joints on the collocation cubic
  for (int j = 0; j < n; ++j) {
    if (rows.knots_only || model.bodies[j].actuated) cubic.push_back(j);
  }
  IntervalDynamicsOptions between;
  between.limit_epsilon = problem.objectives.limit_epsilon;
  between.defect_scale = options.collocation_scale;
  between.torque_scale = options.torque_scale;
  between.limit_scale = options.limit_scale;
  between.integration_step = rows.integration_step;
  between.checks = limit_points(problem.objectives.limit_substeps, dt);
  // The options of an interval by its IntervalLimitRows bits, and whether it has any row.
  std::array<IntervalDynamicsOptions, 4> with_rows;
  std::array<bool, 4> has_rows{};
  for (int bits = 0; bits < 4; ++bits) {
    with_rows[bits] = between;
    with_rows[bits].limit_rows = bits;
    if (bits == kNoLimitRows) with_rows[bits].checks = 0;
    has_rows[bits] = !IntervalDynamicsFactor::layout(model, with_rows[bits]).empty();
  }
  // One scratch per worker for all of them, not a dynamics workspace in every factor.
  const auto workspace = rows.knots_only ? nullptr
                                         : std::make_shared<IntervalWorkspace>(
                                               problem.model, between.integration_step);
  for (int k = 0; k < problem.steps; ++k) {
    out.push_back(make_soft_entry(std::make_shared<GpPriorFactor>(k, n, dt, problem.objectives.qc),
                                  {FactorRole::kGpPrior, k}));
    if (!cubic.empty()) {
      out.push_back(
          make_entry(std::make_shared<CollocationFactor>(k, n, dt, options.collocation_scale, cubic),
                     {FactorRole::kCollocation, k}));
    }
    if (rows.knots_only) continue;
    const int bits = rows.limits.empty() ? kAllLimitRows : rows.limits[k] & kAllLimitRows;
    if (has_rows[bits]) {
      out.push_back(make_entry(
          std::make_shared<IntervalDynamicsFactor>(k, dt, problem.model, with_rows[bits],
                                                   workspace),
          {FactorRole::kInterval, k}));
    }
  }
  return out;
}

std::shared_ptr<CollisionContext> collision_context(
    const Problem& problem, const std::vector<collision::Obstacle>& obstacles,
    const GraphOptions& options) {
  return std::make_shared<CollisionContext>(
      problem.model, obstacles,
      problem.objectives.collision_epsilon + options.collision_query_margin);
}

namespace {

// Hinges of `context` at the free states from `first` on and the sub-steps of the intervals
// that end there, keyed by `role` and `obstacle`.
std::vector<FactorEntry> hinge_entries(const Problem& problem,
                                       const std::shared_ptr<CollisionContext>& context,
                                       FactorRole role, int obstacle, double epsilon,
                                       const GraphOptions& options, int first = 0) {
  std::vector<FactorEntry> out;
  if (!context || context->num_pairs == 0) return out;
  const Objectives& obj = problem.objectives;
  const int N = problem.steps, sub = std::max(0, obj.collision_substeps);
  const double dt = problem.dt();
  for (int k = std::max(first - 1, 0); k <= N; ++k) {
    // The start state is fixed; its clearance is checked before planning.
    if (k > 0 && k >= first) {
      out.push_back(make_entry(
          std::make_shared<CollisionFactor>(k, 0.0, dt, epsilon, options.collision_scale,
                                            context),
          {role, k, 0, obstacle}));
    }
    if (k == N) break;
    for (int i = 1; i <= sub; ++i) {
      out.push_back(make_entry(std::make_shared<CollisionFactor>(
                                   k, static_cast<double>(i) / (sub + 1), dt, epsilon,
                                   options.collision_scale, context),
                               {role, k, i, obstacle}));
    }
  }
  return out;
}

}  // namespace

std::vector<FactorEntry> collision_entries(const Problem& problem,
                                           const std::shared_ptr<CollisionContext>& context,
                                           int obstacle, const GraphOptions& options) {
  return hinge_entries(problem, context, FactorRole::kCollision, obstacle,
                       problem.objectives.collision_epsilon, options);
}

std::vector<FactorEntry> self_collision_entries(const Problem& problem,
                                                const GraphOptions& options, int first) {
  const SelfAndFloor& sf = problem.self_and_floor;
  if (problem.model->collision.empty() || (!sf.self_collision && !sf.floor)) return {};
  std::vector<collision::Obstacle> floor;
  if (sf.floor) floor.push_back(floor_obstacle(*sf.floor));
  SelfPairs self{sf.allowed_pairs, problem.objectives.self_collision_epsilon};
  const Objectives& obj = problem.objectives;
  // The floor takes the self ε too: arms work close to the surface they stand on.
  auto ctx = std::make_shared<CollisionContext>(
      problem.model, floor, obj.self_collision_epsilon + options.collision_query_margin,
      sf.self_collision ? &self : nullptr);
  return hinge_entries(problem, ctx, FactorRole::kSelfCollision, -1, obj.self_collision_epsilon,
                       options, first);
}

std::vector<FactorEntry> tail_entries(
    const Problem& problem, int first, const std::shared_ptr<DynamicsWorkspace>& workspace,
    const std::map<int, std::shared_ptr<CollisionContext>>& obstacles,
    const GraphOptions& options) {
  if (first < 1 || first > problem.steps) {
    throw std::invalid_argument("tail entries: first state " + std::to_string(first) +
                                " is not in 1.." + std::to_string(problem.steps));
  }
  std::vector<FactorEntry> out;
  auto append = [&out](std::vector<FactorEntry>&& more) {
    for (FactorEntry& e : more) out.push_back(std::move(e));
  };
  for (FactorEntry& e : timing_entries(problem, options)) {
    if (e.key.step >= first - 1) out.push_back(std::move(e));
  }
  append(state_entries(problem, workspace, options, first));
  append(self_collision_entries(problem, options, first));
  append(task_entries(problem, workspace, options, first));
  for (const auto& [id, context] : obstacles) {
    append(hinge_entries(problem, context, FactorRole::kCollision, id,
                         problem.objectives.collision_epsilon, options, first));
  }
  return out;
}

FactorEntry start_entry(const Problem& problem) {
  const int n = problem.model->nq();
  Eigen::VectorXd target(2 * n);
  target << problem.start_q,
      (problem.start_qd.size() == n ? problem.start_qd : Eigen::VectorXd::Zero(n));
  FactorEntry e = make_entry(
      StateTargetFactor::soft({q_key(0), v_key(0)}, n, target, kStartPriorWeight),
      {FactorRole::kStart});
  e.anchor = true;
  return e;
}

FactorEntry goal_entry(const Problem& problem, const std::shared_ptr<DynamicsWorkspace>& workspace,
                       const GraphOptions& options) {
  const int N = problem.steps;
  if (problem.goal.kind == Goal::Kind::kJoint) {
    FactorEntry e = make_entry(
        std::make_shared<StateTargetFactor>(std::vector<graph::Key>{q_key(N)},
                                            problem.model->nq(), problem.goal.q, kJointGoalScale),
        {FactorRole::kGoal, N});
    e.anchor = true;
    return e;
  }
  const PoseParts parts = problem.goal.position_only ? PoseParts::kPosition : PoseParts::kFull;
  return make_entry(std::make_shared<PoseFactor>(N, problem.model, workspace, problem.goal.frame,
                                                 problem.goal.pose, parts, options.pose_scale),
                    {FactorRole::kGoal, N});
}

PlanningGraph build_graph(const Problem& problem, const Trajectory& init,
                          const GraphOptions& options, GraphForm form,
                          const IntervalRows& between) {
  if (!problem.model) throw std::invalid_argument("problem has no model");
  const int n = problem.model->nq(), N = problem.steps;
  if (init.q.rows() != N + 1 || init.q.cols() != n || init.qd.rows() != N + 1 ||
      init.qdd.rows() != N + 1) {
    throw std::invalid_argument("initial trajectory has the wrong shape");
  }
  PlanningGraph pg;
  pg.form = form;
  pg.steps = N;
  pg.nq = n;
  pg.dynamics_workspace = std::make_shared<DynamicsWorkspace>(problem.model);
  pg.values = initial_values(problem, init);
  const bool pose_goal = problem.goal.kind == Goal::Kind::kPose;
  const bool with_collision = !problem.obstacles.empty() && !problem.model->collision.empty();
  if (form == GraphForm::kBatch) {
    if (pose_goal) pg.add(goal_entry(problem, pg.dynamics_workspace, options));
    for (FactorEntry& e : timing_entries(problem, options, between)) pg.add(std::move(e));
    for (FactorEntry& e : state_entries(problem, pg.dynamics_workspace, options, 0)) {
      pg.add(std::move(e));
    }
    if (with_collision) {
      auto ctx = collision_context(problem, problem.obstacles, options);
      pg.collision[-1] = ctx;
      for (FactorEntry& e : collision_entries(problem, ctx, -1, options)) pg.add(std::move(e));
    }
    for (FactorEntry& e : self_collision_entries(problem, options)) pg.add(std::move(e));
    for (FactorEntry& e : task_entries(problem, pg.dynamics_workspace, options, 1)) {
      pg.add(std::move(e));
    }
    return pg;
  }
  for (FactorEntry& e : timing_entries(problem, options, between)) pg.add(std::move(e));
  for (FactorEntry& e : state_entries(problem, pg.dynamics_workspace, options, 0)) {
    pg.add(std::move(e));
  }
  for (FactorEntry& e : self_collision_entries(problem, options)) pg.add(std::move(e));
  for (FactorEntry& e : task_entries(problem, pg.dynamics_workspace, options, 1)) {
    pg.add(std::move(e));
  }
  pg.add(start_entry(problem));
  pg.add(goal_entry(problem, pg.dynamics_workspace, options));
  std::set<int> ids;
  for (const collision::Obstacle& o : problem.obstacles) {
    if (!ids.insert(o.id).second) {
      throw std::invalid_argument("obstacle id " + std::to_string(o.id) + " is repeated");
    }
    if (problem.model->collision.empty()) continue;
    auto ctx = collision_context(problem, {o}, options);
    pg.collision[o.id] = ctx;
    for (FactorEntry& e : collision_entries(problem, ctx, o.id, options)) pg.add(std::move(e));
  }
  return pg;
}

double soft_cost(const std::vector<const FactorEntry*>& entries, const graph::Values& values,
                 double* violation) {
  double soft = 0;
  for (const FactorEntry* e : entries) {
    if (!e->constrained) {
      soft += e->factor->error(values);
      continue;
    }
    // Most constraint factors (collision, limits) have no soft rows: no evaluation for the cost.
    if (violation == nullptr && !e->constrained->has_soft_rows()) continue;
    const ConstrainedFactor::Terms t = e->constrained->terms(values);
    soft += t.soft_cost;
    if (violation != nullptr) *violation = std::max(*violation, t.violation);
  }
  return soft;
}

double soft_cost(const std::vector<FactorEntry>& entries, const graph::Values& values,
                 double* violation) {
  std::vector<const FactorEntry*> all;
  all.reserve(entries.size());
  for (const FactorEntry& e : entries) all.push_back(&e);
  return soft_cost(all, values, violation);
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

#include "kinograph/planning/incremental/first_plan.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "kinograph/planning/factors/trajectory_factors.h"
#include "kinograph/planning/validate.h"

namespace kinograph::planning {
namespace {

// μ of the tree as a fraction of the batch's final μ, and its ceiling: a stiff tree sends a
// goal change into worse optima than a moderate one at the same success.
constexpr double kCarriedPenaltyFraction = 0.1;
constexpr double kMaxCarriedPenalty = 1e4;
// A valid plan's μ is at least its largest equality force over this ratio.
constexpr double kMaxForceRatio = 0.1;

// Changes the record's penalty to `mu` keeping the force λ + μc of every constraint row at
// `values` (bounds clipped at 0), so that a point stationary for the old augmented Lagrangian
// stays stationary for the new one. Exact for mu ≤ the old μ, the only use here.
void keep_forces(const ConstrainedFactor& f, const graph::Values& values, double mu,
                 Multipliers& m, Eigen::VectorXd& z) {
  const double d = m.penalty - mu;
  if (d == 0) return;
  f.values_at(values, z);
  for (int i = 0; i < f.residual_dim(); ++i) {
    const RowSpec& row = f.rows()[i];
    if (row.kind == RowKind::kEquality) {
      m.lower[i] += d * (z[i] - row.lower) / row.scale;
    } else if (row.kind == RowKind::kBounds) {
      if (std::isfinite(row.lower))
        m.lower[i] = std::max(0.0, m.lower[i] + d * (row.lower - z[i]) / row.scale);
      if (std::isfinite(row.upper))
        m.upper[i] = std::max(0.0, m.upper[i] + d * (z[i] - row.upper) / row.scale);
    }
  }
}

// The joint goal's multipliers are the force that held q_N fixed: stationarity of the augmented
// Lagrangian at c = 0 gives λ/s = −∂(rest of the cost)/∂q_N.
void set_goal_multipliers(IncrementalTree& tree, const graph::Values& values, int N, int n) {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  const FactorEntry* goal = nullptr;
  for (const FactorEntry& e : tree.entries) {
    if (e.key.role == FactorRole::kGoal) {
      goal = &e;
      continue;
    }
    const auto& keys = e.factor->keys();
    const auto it = std::find(keys.begin(), keys.end(), q_key(N));
    if (it == keys.end()) continue;
    e.factor->linearize(values, r, J);
    const int col = e.factor->block_offsets()[it - keys.begin()];
    g += J.middleCols(col, n).transpose() * r;
  }
  if (goal == nullptr || !goal->anchor) return;
  const double goal_scale = goal->constrained->rows().front().scale;
  Multipliers& m = tree.constraints.at(goal->key);
  m.lower = -goal_scale * g;
  m.upper.setZero(n);
}

// Frees the start and a joint goal (they become anchor factors) and builds the tree there.
bool finish_tree(IncrementalTree& tree, graph::Values values, const Problem& problem) {
  const int N = problem.steps;
  values.set_fixed(q_key(0), false);
  values.set_fixed(v_key(0), false);
  values.set_fixed(q_key(N), false);
  for (const FactorEntry& e : tree.entries) {
    if (e.constrained && e.constrained->has_constraints()) tree.constraints.bind(e);
  }
  if (problem.goal.kind == Goal::Kind::kJoint) {
    set_goal_multipliers(tree, values, N, problem.model->nq());
  }
  const graph::ISAM2Result r = tree.build(values);
  if (!r.ok()) spdlog::warn("incremental planner: building the Bayes tree: {}", r.reason);
  return r.ok();
}

double largest_equality_force(const PlanningGraph& pg, const ConstraintState& cs) {
  double force = 0;
  for (const FactorEntry* e : pg.constraints(false)) {
    const Multipliers& m = cs.at(e->key);
    for (int i = 0; i < e->constrained->residual_dim(); ++i) {
      if (e->constrained->rows()[i].kind == RowKind::kEquality) {
        force = std::max(force, std::abs(m.lower[i]));
      }
    }
  }
  return force;
}

// Per-obstacle collision entries whose multipliers are the batch factors' rows of the same
// (state, sub-step, robot geometry, obstacle).
bool split_collision(IncrementalTree& tree, const Problem& problem, const PlanningGraph& pg,
                     ConstraintState& cs, const GraphOptions& options) {
  std::vector<const FactorEntry*> batch;
  for (const FactorEntry& e : pg.entries) {
    if (e.key.role == FactorRole::kCollision) batch.push_back(&e);
  }
  const auto all = pg.collision.find(-1);
  const CollisionContext* batch_ctx = all == pg.collision.end() ? nullptr : all->second.get();
  std::set<int> ids;
  for (const collision::Obstacle& o : problem.obstacles) {
    if (!ids.insert(o.id).second) return false;
    if (problem.model->collision.empty()) continue;
    auto ctx = collision_context(problem, {o}, options);
    tree.contexts[o.id] = ctx;
    std::vector<FactorEntry> es = collision_entries(problem, ctx, o.id, options);
    int column = -1;  // the obstacle's column in the batch context
    if (batch_ctx != nullptr) {
      const auto& bid = batch_ctx->obstacle_ids;
      const auto it = std::find(bid.begin(), bid.end(), o.id);
      if (it != bid.end()) column = static_cast<int>(it - bid.begin());
    }
    const bool carry = column >= 0 && es.size() == batch.size();
    if (!es.empty() && !carry) {
      spdlog::warn("incremental planner: obstacle {}'s collision multipliers not carried", o.id);
    }
    for (size_t i = 0; i < es.size(); ++i) {
      cs.bind(es[i]);
      if (carry) {
        const Multipliers& from = cs.at(batch[i]->key);
        Multipliers& to = cs.at(es[i].key);
        for (int g : ctx->geoms) {
          const int a = ctx->row_of[g][0], b = batch_ctx->row_of[g][column];
          if (a < 0 || b < 0) continue;
          to.lower[a] = from.lower[b];
          to.upper[a] = from.upper[b];
        }
      }
      tree.entries.push_back(std::move(es[i]));
    }
  }
  for (const FactorEntry* e : batch) cs.erase(e->key);
  return true;
}

}  // namespace

double carried_penalty(double batch_penalty, double largest_force, bool valid, double floor,
                       double cap) {
  double mu = std::clamp(kCarriedPenaltyFraction * batch_penalty, floor, kMaxCarriedPenalty);
  if (valid) mu = std::max(mu, std::min(largest_force / kMaxForceRatio, cap));
  return mu;
}

std::unique_ptr<IncrementalTree> carry_batch_solution(const Problem& problem,
                                                      BatchSolution& solution, bool valid,
                                                      const BatchPlannerOptions& batch,
                                                      const graph::ISAM2Options& isam2) {
  PlanningGraph& pg = solution.graph;
  ConstraintState& cs = solution.constraints;
  if (pg.steps != problem.steps || pg.nq != problem.model->nq() || pg.values.size() == 0) {
    return nullptr;
  }
  const double mu =
      carried_penalty(cs.penalty(), largest_equality_force(pg, cs), valid,
                      batch.augmented_lagrangian.initial_penalty,
                      batch.augmented_lagrangian.max_penalty);
  spdlog::debug("iDFGP first plan: carried mu {:.3g}", mu);
  auto tree = std::make_unique<IncrementalTree>(isam2);
  tree->workspace = pg.dynamics_workspace;
  std::optional<FactorEntry> pose_goal;
  Eigen::VectorXd z;
  for (const FactorEntry& e : pg.entries) {
    if (e.constrained && e.constrained->has_constraints()) {
      keep_forces(*e.constrained, pg.values, mu, cs.at(e.key), z);
    }
    if (e.key.role == FactorRole::kCollision) continue;
    if (e.key.role == FactorRole::kGoal) {
      pose_goal = e;
      continue;
    }
    tree->entries.push_back(e);
  }
  tree->entries.push_back(start_entry(problem));
  tree->entries.push_back(pose_goal ? *pose_goal
                                    : goal_entry(problem, tree->workspace, batch.graph));
  if (!split_collision(*tree, problem, pg, cs, batch.graph)) return nullptr;
  cs.set_penalty(mu);
  tree->constraints = std::move(cs);
  if (!finish_tree(*tree, pg.values, problem)) return nullptr;
  return tree;
}

std::unique_ptr<IncrementalTree> solve_incremental_graph(const Problem& problem,
                                                         const Trajectory& init,
                                                         const std::string& method,
                                                         const BatchPlannerOptions& batch,
                                                         const graph::ISAM2Options& isam2,
                                                         Plan& plan) {
  PlanningGraph pg = build_graph(problem, init, batch.graph, GraphForm::kIncremental);
  if (batch.formulation == Formulation::kDynamicFactorGraph) {
    use_dfg_dynamics(pg, problem, batch.graph, batch.dfg);
  }
  auto tree = std::make_unique<IncrementalTree>(isam2);
  AugmentedLagrangian al(pg.constraints(false), tree->constraints, batch.augmented_lagrangian);
  const OuterLoopResult r =
      solve_outer_loop(pg.graph, pg.values, al, outer_loop_options(batch), problem.name);
  tree->workspace = pg.dynamics_workspace;
  tree->contexts = pg.collision;
  tree->entries = pg.entries;
  tree->constraints.set_penalty(std::clamp(al.penalty(), batch.augmented_lagrangian.initial_penalty,
                                           kMaxCarriedPenalty));
  plan = solved_plan(problem, pg, r, method, batch);
  finish_tree(*tree, pg.values, problem);
  return tree;
}

}  // namespace kinograph::planning

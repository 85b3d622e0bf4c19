#include "kinograph/planning/incremental/incremental_planner.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <sstream>

#include "kinograph/graph/stopwatch.h"
#include "kinograph/planning/incremental/first_plan.h"
#include "kinograph/planning/incremental/incremental_tree.h"
#include "kinograph/planning/incremental/stopping_rule.h"
#include "kinograph/planning/problem_check.h"
#include "kinograph/planning/solver/violation_text.h"
#include "kinograph/planning/validate.h"

namespace kinograph::planning {
namespace {

using Clock = std::chrono::steady_clock;
using graph::seconds_since;

// The plan keeps the measured start itself when the estimate is this close to it (rad, rad/s):
// the start prior holds x_0 to about the validator's threshold after a large change.
constexpr double kStartSnap = 1e-4;


// Whether a bound row holds a positive multiplier (which shrinks once the row is inactive).
bool has_bound_multipliers(const ConstrainedFactor& f, const Multipliers& m) {
  for (int i = 0; i < f.residual_dim(); ++i) {
    if (f.rows()[i].kind == RowKind::kBounds && (m.lower[i] > 0 || m.upper[i] > 0)) return true;
  }
  return false;
}

bool same_goal(const Goal& a, const Goal& b) {
  return a.kind == b.kind && a.q == b.q && a.frame == b.frame &&
         a.pose.matrix() == b.pose.matrix() && a.position_only == b.position_only &&
         a.joint_tolerance == b.joint_tolerance && a.position_tolerance == b.position_tolerance &&
         a.orientation_tolerance == b.orientation_tolerance;
}

bool same_tasks(const std::vector<TaskConstraint>& a, const std::vector<TaskConstraint>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(),
                    [](const TaskConstraint& x, const TaskConstraint& y) {
                      return x.frame == y.frame && x.orientation_only == y.orientation_only &&
                             x.target.matrix() == y.target.matrix() && x.tolerance == y.tolerance;
                    });
}

// Steps from here on name the variables shift() retired (a trajectory's steps stay far below).
constexpr uint32_t kRetiredStep = 0x80000000u;
// How close the start of a shifted replan must be to the tree's knot (rad, rad/s): the tree's
// estimate may lie a little off the plan that was answered (a batch plan carried into it, then
// settled), and the start prior re-anchors the rest, as a measured start does.
constexpr double kShiftStartTolerance = 0.05;

// An initial trajectory through `q, qd, qdd` that starts at the problem's start and ends at
// rest.
Trajectory anchored(const Problem& problem, const Eigen::MatrixXd& q, const Eigen::MatrixXd& qd,
                    const Eigen::MatrixXd& qdd) {
  const int n = problem.model->nq(), N = problem.steps;
  Trajectory init{q, qd, qdd};
  init.q.row(0) = problem.start_q.transpose();
  if (problem.start_qd.size() == n) {
    init.qd.row(0) = problem.start_qd.transpose();
  } else {
    init.qd.row(0).setZero();
  }
  init.qd.row(N).setZero();
  init.qdd.row(N).setZero();
  return init;
}

bool tracked(const FactorEntry& e) { return e.constrained && e.constrained->has_constraints(); }

}  // namespace

graph::ISAM2Options default_incremental_isam2() {
  graph::ISAM2Options o;
  o.relinearize_threshold = 0.01;
  // Marquardt damping lingers less: while it lasts it stiffens the smooth modes of the
  // trajectory, and each update then bends only part of it.
  o.lambda_decrease = 100;
  // A replan answers with the first update whose plan validates: the linearization at its
  // estimate is left to prepare(), which runs after the answer.
  o.linearize_at_evaluation = false;
  return o;
}

IncrementalPlanner::IncrementalPlanner(IncrementalPlannerOptions options)
    : options_(std::move(options)) {}
IncrementalPlanner::~IncrementalPlanner() = default;

Plan IncrementalPlanner::make_plan(bool with_stats) const {
  const graph::Values& values = tree_->isam->estimate();
  const int n = problem_.model->nq(), N = problem_.steps;
  Trajectory tr = read_trajectory(values, N, n);
  // The start is data, not a variable; a start the solve did not reach is left for the
  // validator to reject.
  const Eigen::VectorXd qd0 =
      problem_.start_qd.size() == n ? problem_.start_qd : Eigen::VectorXd::Zero(n);
  const double start_gap =
      std::max((tr.q.row(0).transpose() - problem_.start_q).cwiseAbs().maxCoeff(),
               (tr.qd.row(0).transpose() - qd0).cwiseAbs().maxCoeff());
  if (start_gap <= kStartSnap) {
    tr.q.row(0) = problem_.start_q.transpose();
    tr.qd.row(0) = qd0.transpose();
  }
  Plan plan = plan_from_trajectory(problem_, tr);
  read_dfg_torques(plan, values, *problem_.model, options_.batch.dfg.keys);
  plan.stats.method = "incremental";
  // Without stats this is the stopping rule's check, which needs only the verdict.
  plan.validation = validate(problem_, plan, options_.batch.validation, !with_stats);
  if (with_stats) {
    double worst = 0;
    plan.stats.cost = tree_->soft_cost(&worst);
    plan.stats.max_constraint_violation = worst;
  }
  return plan;
}

Plan IncrementalPlanner::plan(const Problem& problem, const Plan* warm) {
  const auto t0 = Clock::now();
  if (warm != nullptr) {
    const std::string error = check_problem(problem);
    if (!error.empty()) return failed_plan("batch-W", PlanStatus::kInvalidProblem, error);
    Plan p;
    try {
      const Trajectory w = warm_start(problem, *warm);
      tree_ = solve_incremental_graph(problem, anchored(problem, w.q, w.qd, w.qdd), "batch-W",
                                      options_.batch, options_.isam2, p);
    } catch (const std::exception& e) {
      return failed_plan("batch-W", PlanStatus::kInvalidProblem, e.what());
    }
    problem_ = problem;
    stats_ = IncrementalStats();
    stats_.method = "batch-W";
    stats_.penalty = tree_->constraints.penalty();
    p.stats.solve_time_s = seconds_since(t0);
    plan_ = p;
    spdlog::debug("iDFGP warm start on the incremental graph: {}, {:.1f} ms",
                  p.success() ? "valid" : "not valid", p.stats.solve_time_s * 1e3);
    if (!p.success()) {
      if (std::optional<Plan> batch = carried_batch_plan(problem, warm)) {
        add_work(batch->stats, p.stats);
        p = std::move(*batch);
      }
      p.stats.solve_time_s = seconds_since(t0);
    }
    return p;
  }
  // The batch planner's own initializations (straight line, detours) find the way; its final
  // graph, values and multipliers become the tree's (no second solve).
  BatchSolution solution;
  const Plan batch = BatchPlanner(options_.batch).plan(problem, nullptr, &solution);
  if (batch.stats.status == PlanStatus::kInvalidProblem || batch.q.rows() != problem.steps + 1 ||
      !batch.q.allFinite()) {
    return batch;
  }
  tree_.reset();
  // A batch plan that does not validate is carried as it is: where the batch planner's own
  // attempts all failed, neither settling it nor a re-solve on the incremental graph makes it
  // valid; they would only add their time to the failure.
  std::optional<Plan> carried = carry_first_plan(problem, batch, solution);
  if (carried) {
    carried->stats.solve_time_s = seconds_since(t0);
    plan_ = *carried;
    return *carried;
  }
  // Not carried: the outer loop on the incremental graph builds the tree.
  Plan p;
  try {
    tree_ = solve_incremental_graph(problem, anchored(problem, batch.q, batch.qd, batch.qdd),
                                    "batch-L", options_.batch, options_.isam2, p);
  } catch (const std::exception& e) {
    return failed_plan("batch-L", PlanStatus::kInvalidProblem, e.what());
  }
  problem_ = problem;
  stats_ = IncrementalStats();
  stats_.method = "batch-L";
  plan_ = p;
  if (p.success()) settle(p, /*first_plan=*/false);
  stats_.method = p.stats.method;
  if (!p.success() && batch.success()) {
    const SolveStats own = p.stats;
    // The re-solve missed what the batch plan reached: answer with the batch plan (the tree
    // stays at the re-solve's estimate, near it).
    p = batch;
    p.stats.iterations = own.iterations;
    p.stats.outer_iterations = own.outer_iterations;
    p.stats.linear_solves = own.linear_solves;
    p.stats.times = own.times;
  }
  add_work(p.stats, batch.stats);
  p.stats.solve_time_s = seconds_since(t0);
  plan_ = p;
  return p;
}

std::optional<Plan> IncrementalPlanner::carried_batch_plan(const Problem& problem,
                                                           const Plan* warm) {
  BatchSolution solution;
  const Plan batch = BatchPlanner(options_.batch).plan(problem, warm, &solution);
  if (!batch.success()) return std::nullopt;
  std::unique_ptr<IncrementalTree> before = std::move(tree_);
  std::optional<Plan> carried = carry_first_plan(problem, batch, solution);
  if (!carried || !carried->success()) {
    tree_ = std::move(before);  // carry_first_plan changed nothing else when it failed
    return std::nullopt;
  }
  plan_ = *carried;
  return carried;
}

std::optional<Plan> IncrementalPlanner::carry_first_plan(const Problem& problem, const Plan& batch,
                                                         BatchSolution& solution) {
  try {
    tree_ = carry_batch_solution(problem, solution, batch.success(), options_.batch,
                                 options_.isam2);
  } catch (const std::exception& e) {
    spdlog::warn("incremental planner: carrying the batch solution: {}", e.what());
    tree_.reset();
  }
  if (!tree_) return std::nullopt;
  problem_ = problem;
  stats_ = IncrementalStats();
  stats_.method = batch.stats.method;
  stats_.penalty = tree_->constraints.penalty();
  plan_ = batch;
  Plan p = batch;
  if (batch.success() && options_.settle_first_plan) settle(p, /*first_plan=*/true);
  stats_.method = batch.stats.method;
  return p;
}

void IncrementalPlanner::settle(Plan& plan, bool first_plan) {
  const IncrementalTree::Snapshot before = tree_->snapshot();
  const Plan settled = replan_within(ProblemChange(), kSettleUpdates);
  spdlog::debug("iDFGP settle: {} updates, {} rounds, {:.1f} ms, {}, cost {:.6g} (answered {:.6g})",
                stats_.updates, stats_.rounds, stats_.incremental_time_s * 1e3,
                settled.success() ? "valid" : "not valid", settled.stats.cost, plan.stats.cost);
  // A carried first plan is replaced by a valid settled plan that costs no more; a re-solved
  // one by any valid settled plan.
  const bool take = settled.success() && (!first_plan || settled.stats.cost <= plan.stats.cost);
  // A settled tree that validates is kept even when its plan costs a little more (the next
  // replan starts at its optimum); one that does not returns to the answered plan.
  if (!settled.success()) {
    spdlog::debug("iDFGP: the settled tree does not validate; rebuilt at the answered plan");
    if (!tree_->restore(before)) {
      spdlog::warn("incremental planner: the Bayes tree could not be rebuilt at the plan");
    }
  }
  if (take) {
    const SolveStats own = plan.stats;
    plan = settled;
    plan.stats.method = own.method;
    add_work(plan.stats, own);
  }
}

Plan IncrementalPlanner::replan(const ProblemChange& change) {
  return replan_within(change, options_.max_updates);
}

Plan IncrementalPlanner::replan_within(const ProblemChange& change, int max_updates) {
  const auto t0 = Clock::now();
  stats_ = IncrementalStats();  // a refused change must not report the previous replan's figures
  stats_.method = "incremental";
  if (!tree_) return failed_plan("incremental", PlanStatus::kNoPlan, "replan needs a plan first");
  // The changed problem; checked before any state changes.
  Problem next;
  std::set<int> changed_obstacles;
  std::string error = apply_change(problem_, change, next, changed_obstacles);
  if (error.empty()) error = check_problem(next);
  if (!error.empty()) return failed_plan("incremental", PlanStatus::kInvalidProblem, error);
  try {
    replace_factors(change, next, changed_obstacles);
  } catch (const std::exception& e) {
    return failed_plan("incremental", PlanStatus::kInvalidProblem, e.what());
  }
  problem_ = next;
  return answer_replan(t0, max_updates);
}

Plan IncrementalPlanner::answer_replan(Clock::time_point t0, int max_updates) {
  tree_->compact_if_sparse();
  PlanStatus status = PlanStatus::kMaxUpdates;
  std::string reason;
  std::optional<Plan> valid_plan = run_updates(plan_.stats.cost, max_updates, status, reason);
  stats_.penalty = tree_->constraints.penalty();
  stats_.incremental_time_s = seconds_since(t0);
  Plan plan = valid_plan ? std::move(*valid_plan) : make_plan();
  plan.stats.status = status;
  plan.stats.reason = reason;
  plan.stats.iterations = stats_.updates;
  plan.stats.outer_iterations = stats_.rounds;
  plan.stats.linear_solves = stats_.updates;
  if (reason.empty()) {
    std::ostringstream os;
    os << stats_.updates << " ISAM2 updates, " << stats_.rounds << " multiplier rounds, "
       << stats_.variables_reeliminated << " variables re-eliminated";
    plan.stats.reason = os.str();
  }
  if (!valid_plan && (status == PlanStatus::kMaxUpdates || status == PlanStatus::kMaxRounds)) {
    std::vector<const FactorEntry*> constraints;
    for (const FactorEntry& e : tree_->entries) {
      if (tracked(e)) constraints.push_back(&e);
    }
    const ConstraintReport worst = worst_constraint(constraints, tree_->isam->estimate());
    if (worst.scaled_violation > options_.batch.outer_loop.constraint_tolerance) {
      plan.stats.reason += "; the worst violation: " + describe_violation(problem_, worst);
    }
  }
  plan.stats.solve_time_s = seconds_since(t0);
  plan_ = plan;
  return plan;
}

std::string IncrementalPlanner::shift_refusal(const Problem& next, int m) const {
  if (!tree_) return "there is no plan to go on from";
  if (options_.batch.formulation != Formulation::kCondensed) {
    return "the DFG formulation's variables are not shifted";
  }
  const int N = problem_.steps;
  if (next.steps != N || next.horizon != problem_.horizon) return "the steps or horizon differ";
  if (m < 1 || m > N - 2) {
    return "a start " + std::to_string(m) + " knots on is not within 1.." + std::to_string(N - 2);
  }
  if (next.model != problem_.model || !same_goal(next.goal, problem_.goal) ||
      !same_tasks(next.task_constraints, problem_.task_constraints)) {
    return "the robot, goal or task constraints differ";
  }
  for (const graph::Key& k : tree_->isam->estimate().keys()) {
    if (k.kind() != 'q' && k.kind() != 'v' && k.kind() != 'a') {
      return "the graph has a variable " + k.to_string() + " that is no state";
    }
  }
  const int n = problem_.model->nq();
  const graph::Values& x = tree_->isam->estimate();
  const Eigen::VectorXd qd0 = next.start_qd.size() == n ? next.start_qd : Eigen::VectorXd::Zero(n);
  if (next.start_q.size() != n ||
      (x.at(q_key(m)) - next.start_q).cwiseAbs().maxCoeff() > kShiftStartTolerance ||
      (x.at(v_key(m)) - qd0).cwiseAbs().maxCoeff() > kShiftStartTolerance) {
    return "the start is not where the plan has the robot at knot " + std::to_string(m);
  }
  return "";
}

Plan IncrementalPlanner::shift(const Problem& next, int m) {
  const auto t0 = Clock::now();
  stats_ = IncrementalStats();
  stats_.method = "incremental";
  std::string error = shift_refusal(next, m);
  if (error.empty()) error = check_problem(next);
  if (!error.empty()) return failed_plan("incremental", PlanStatus::kInvalidProblem, error);
  IncrementalTree& t = *tree_;
  const int N = problem_.steps, n = problem_.model->nq();
  const GraphOptions& go = options_.batch.graph;
  // Obstacles whose factors are replaced: new, moved, removed or moving along a trajectory
  // (whose times count from the start).
  std::set<int> changed;
  std::map<int, const collision::Obstacle*> before;
  for (const collision::Obstacle& o : problem_.obstacles) before[o.id] = &o;
  for (const collision::Obstacle& o : next.obstacles) {
    const auto it = before.find(o.id);
    if (it == before.end() || !collision::same_static_obstacle(*it->second, o)) {
      changed.insert(o.id);
    }
    if (it != before.end()) before.erase(it);
  }
  for (const auto& [id, o] : before) changed.insert(id);
  // An obstacle without a collision world of its own in the tree gets one, and new factors.
  for (const collision::Obstacle& o : next.obstacles) {
    if (tree_->contexts.count(o.id) == 0 || !tree_->contexts.at(o.id)) changed.insert(o.id);
  }

  // Steps from m on count from 0; the states before m and the end state's fixed rest (v_N,
  // a_N) are retired under steps of their own.
  const uint32_t retired = kRetiredStep + retired_steps_;
  const auto rename = [&](graph::Key k) {
    const uint32_t s = k.step();
    if (s >= kRetiredStep) return k;
    if (s < static_cast<uint32_t>(m)) return graph::Key(k.kind(), k.index(), retired + s);
    if (s == static_cast<uint32_t>(N) && k.kind() != 'q') {
      return graph::Key(k.kind(), k.index(), retired + m);
    }
    return graph::Key(k.kind(), k.index(), s - m);
  };
  // An entry's state span after the shift: [step, step] for a state, [step, step + 1] for an
  // interval (its sub-step hinges included).
  const auto spans_interval = [](const FactorKey& k) {
    return k.role == FactorRole::kGpPrior || k.role == FactorRole::kCollocation ||
           k.role == FactorRole::kInterval ||
           ((k.role == FactorRole::kCollision || k.role == FactorRole::kSelfCollision) &&
            k.sub > 0);
  };
  const int first_new = N - m;  // states first_new..N get new factors
  std::vector<FactorEntry> keep, added;
  std::vector<size_t> removed_slots;
  for (const FactorEntry& e : t.entries) {
    FactorKey k = e.key;
    const bool anchor_role = k.role == FactorRole::kStart || k.role == FactorRole::kGoal;
    k.step -= m;
    const int last_state = k.step + (spans_interval(k) ? 1 : 0);
    const bool gone = anchor_role || k.step < 0 || last_state >= first_new ||
                      (k.role == FactorRole::kCollision && changed.count(k.index) > 0);
    if (gone) {
      removed_slots.push_back(e.slot);
      continue;
    }
    keep.push_back(e);
    keep.back().key = k;
  }
  // Built before anything changes: the tree stays as it was if a factor cannot be built.
  std::map<int, std::shared_ptr<CollisionContext>> contexts;  // of every obstacle of `next`
  std::map<int, std::shared_ptr<CollisionContext>> kept_contexts;
  try {
    for (const collision::Obstacle& o : next.obstacles) {
      if (next.model->collision.empty()) break;
      if (changed.count(o.id) == 0) {
        contexts[o.id] = kept_contexts[o.id] = t.contexts.at(o.id);
        continue;
      }
      contexts[o.id] = collision_context(next, {o}, go);
      for (FactorEntry& e : collision_entries(next, contexts[o.id], o.id, go)) {
        added.push_back(std::move(e));
      }
    }
    added.push_back(start_entry(next));
    added.push_back(goal_entry(next, t.workspace, go));
    for (FactorEntry& e : tail_entries(next, first_new, t.workspace, kept_contexts, go)) {
      added.push_back(std::move(e));
    }
  } catch (const std::exception& e) {
    return failed_plan("incremental", PlanStatus::kInvalidProblem, e.what());
  }
  // The new states: at rest where the plan ends (its last state's velocity and acceleration
  // free now, the new end's fixed at rest).
  const graph::Values& x = t.isam->estimate();
  const Eigen::VectorXd q_end = x.at(q_key(N)), zero = Eigen::VectorXd::Zero(n);
  std::vector<graph::Key> leaving;
  for (int s = 0; s < m; ++s) {
    for (const graph::Key& k : {q_key(s), v_key(s), a_key(s)}) leaving.push_back(rename(k));
  }

  t.rename(rename);
  t.retire(leaving);
  graph::Values fresh;
  fresh.insert(v_key(first_new), zero);
  fresh.insert(a_key(first_new), zero);
  for (int k = first_new + 1; k <= N; ++k) {
    fresh.insert(q_key(k), q_end);
    fresh.insert(v_key(k), zero);
    fresh.insert(a_key(k), zero);
  }
  fresh.set_fixed(v_key(N));
  fresh.set_fixed(a_key(N));
  t.queue_values(fresh);
  // Multipliers move with their factors; those of the states left behind and of removed
  // obstacles are dropped.
  std::set<int> removed;
  for (const auto& entry : before) removed.insert(entry.first);
  t.constraints.rename([m, &removed](const FactorKey& k) -> std::optional<FactorKey> {
    if (k.role == FactorRole::kStart || k.role == FactorRole::kGoal) return k;
    if (k.role == FactorRole::kCollision && removed.count(k.index) > 0) return std::nullopt;
    FactorKey to = k;
    to.step -= m;
    if (to.step < 0) return std::nullopt;
    return to;
  });
  t.contexts = std::move(contexts);
  stats_.factors_replaced = static_cast<int>(removed_slots.size());
  stats_.factors_added = static_cast<int>(added.size());
  t.replace(std::move(keep), std::move(added), removed_slots);
  retired_steps_ += static_cast<uint32_t>(m) + 1;
  problem_ = next;
  return answer_replan(t0, options_.max_updates);
}

void IncrementalPlanner::replace_factors(const ProblemChange& change, const Problem& next,
                                         const std::set<int>& changed_obstacles) {
  IncrementalTree& t = *tree_;
  const bool timing = change.horizon.has_value() && *change.horizon != problem_.horizon;
  const GraphOptions& go = options_.batch.graph;
  auto replaced = [&](const FactorKey& k) {
    switch (k.role) {
      case FactorRole::kStart: return change.start_q.has_value() || change.start_qd.has_value();
      case FactorRole::kGoal: return change.goal.has_value();
      case FactorRole::kCollision: return timing || changed_obstacles.count(k.index) > 0;
      default: return timing && k.depends_on_dt();
    }
  };
  // Copies: the tree stays as it was if building a replacement throws.
  std::vector<FactorEntry> keep, added;
  std::vector<size_t> removed_slots;
  std::vector<FactorKey> dropped;  // a removed obstacle's keys: no replacement carries them
  const std::set<int> removed_ids(change.remove.begin(), change.remove.end());
  for (const FactorEntry& e : t.entries) {
    if (!replaced(e.key)) {
      keep.push_back(e);
      continue;
    }
    removed_slots.push_back(e.slot);
    if (e.key.role == FactorRole::kCollision && removed_ids.count(e.key.index) > 0) {
      dropped.push_back(e.key);
    }
  }
  if (change.start_q || change.start_qd) added.push_back(start_entry(next));
  if (change.goal) added.push_back(goal_entry(next, t.workspace, go));
  if (timing) {
    for (FactorEntry& e : timing_entries(next, go)) added.push_back(std::move(e));
    for (FactorEntry& e : self_collision_entries(next, go)) added.push_back(std::move(e));
  }
  for (const collision::Obstacle& o : next.obstacles) {
    if (!timing && changed_obstacles.count(o.id) == 0) continue;
    // A static obstacle that keeps its shape is moved in its own collision world (building
    // one costs more than the replan); otherwise the world is rebuilt.
    std::shared_ptr<CollisionContext> ctx;
    const auto old = std::find_if(problem_.obstacles.begin(), problem_.obstacles.end(),
                                  [&o](const collision::Obstacle& x) { return x.id == o.id; });
    if (old != problem_.obstacles.end() && t.contexts.count(o.id) > 0 &&
        collision::same_shape(old->shape, o.shape) && !o.is_moving() && !old->is_moving()) {
      ctx = t.contexts[o.id];
      if (ctx && !ctx->move_obstacle(o.id, o.pose).ok) ctx = nullptr;
    }
    if (next.model->collision.empty()) continue;
    if (!ctx) ctx = collision_context(next, {o}, go);
    t.contexts[o.id] = ctx;
    for (FactorEntry& e : collision_entries(next, ctx, o.id, go)) added.push_back(std::move(e));
  }
  for (int id : change.remove) t.contexts.erase(id);
  // Multipliers carry to a replacement under the same key.
  for (const FactorKey& k : dropped) t.constraints.erase(k);
  stats_.factors_replaced = static_cast<int>(removed_slots.size());
  stats_.factors_added = static_cast<int>(added.size());
  t.replace(std::move(keep), std::move(added), removed_slots);
}

std::optional<Plan> IncrementalPlanner::run_updates(double previous_cost, int max_updates,
                                                    PlanStatus& status, std::string& reason) {
  IncrementalTree& t = *tree_;
  const AugmentedLagrangianOptions& alo = options_.batch.augmented_lagrangian;
  StoppingRule rule(options_.batch.outer_loop.constraint_tolerance, previous_cost,
                    options_.stop_at_first_valid);
  bool polish = false;
  t.last_violation = -1;
  std::vector<double> violations;
  std::optional<Plan> answer;
  while (stats_.updates < max_updates) {
    // Every update relinearizes every moved variable: with the threshold alone a damped step
    // pulls the others back toward their linearization point, against the stiff start prior.
    const graph::ISAM2Result r = t.update(/*force_relinearize=*/true, stats_);
    if (!r.ok()) {
      status = r.status == graph::ISAM2Status::kSingular ? PlanStatus::kSingular
                                                          : PlanStatus::kNonFinite;
      reason = r.reason;
      break;
    }
    const double e = r.error_evaluated ? r.error_after : t.isam->error();
    spdlog::debug("iDFGP update {}{}: error {:.6g} -> {:.6g}{}, {} relinearized, {} cliques, "
                  "lambda {:.3g}, {:.2f} ms",
                  stats_.updates, polish ? " (polish)" : "", r.error_before, e,
                  r.error_increased ? " (rose)" : "", r.variables_relinearized,
                  r.cliques_reeliminated, r.lambda, r.total_s * 1e3);
    if (polish) {
      status = PlanStatus::kConverged;
      break;
    }
    if (options_.stop_at_first_valid && rule.accept(t.soft_cost())) {
      Plan candidate = make_plan(/*with_stats=*/false);
      if (candidate.success()) {
        double worst = 0;  // a valid plan's validation is complete
        candidate.stats.cost = t.soft_cost(&worst);
        candidate.stats.max_constraint_violation = worst;
        answer = std::move(candidate);
        status = PlanStatus::kConverged;
        break;
      }
    }
    if (!rule.settled(r.error_before, e)) continue;
    // Settled at this multiplier estimate: check the constraints.
    const graph::Values& values = t.isam->estimate();
    double worst = 0;
    violations.assign(t.entries.size(), 0.0);
    for (size_t i = 0; i < t.entries.size(); ++i) {
      if (!tracked(t.entries[i])) continue;
      violations[i] = t.entries[i].constrained->scaled_violation(values);
      worst = std::max(worst, violations[i]);
    }
    spdlog::debug("iDFGP round {}: mu {:.3g}, worst scaled violation {:.3g}", stats_.rounds,
                  t.constraints.penalty(), worst);
    const StoppingRule::Next next = rule.after_settling(worst);
    if (next == StoppingRule::Next::kSettleObjective) continue;
    if (next == StoppingRule::Next::kPolish) {
      if (stats_.updates >= max_updates) {
        status = PlanStatus::kConverged;
        break;
      }
      polish = true;  // one update relinearizing every moved variable (ISAM2's threshold)
      continue;
    }
    if (stats_.rounds >= options_.max_rounds) {
      status = PlanStatus::kMaxRounds;
      break;
    }
    ++stats_.rounds;
    // The penalty grows when the violation did not shrink enough since the last round.
    const bool grow = t.last_violation >= 0 && worst > alo.required_decrease * t.last_violation &&
                      t.constraints.penalty() < alo.max_penalty;
    t.last_violation = worst;
    stats_.factors_readded += multiplier_round(violations, grow, rule);
  }
  return answer;
}

int IncrementalPlanner::multiplier_round(const std::vector<double>& violations, bool grow,
                                         const StoppingRule& rule) {
  IncrementalTree& t = *tree_;
  const graph::Values& values = t.isam->estimate();
  const double mu = t.constraints.penalty();
  int readded = 0;
  for (size_t i = 0; i < t.entries.size(); ++i) {
    const FactorEntry& e = t.entries[i];
    if (!tracked(e)) continue;
    Multipliers& m = t.constraints.at(e.key);
    // Nothing to update where the rows hold and no bound multiplier is left to shrink.
    if (!grow && rule.negligible(violations[i]) && !has_bound_multipliers(*e.constrained, m)) {
      continue;
    }
    const Eigen::VectorXd lo = m.lower, up = m.upper;
    e.constrained->update_multipliers(values, m);
    const double change =
        std::max((m.lower - lo).cwiseAbs().maxCoeff(), (m.upper - up).cwiseAbs().maxCoeff()) / mu;
    if (!grow && rule.negligible(change)) {
      m.lower = lo;
      m.upper = up;
      continue;
    }
    t.queue_remove(e.slot);
    t.queue_add(i);
    ++readded;
  }
  if (grow) {
    const AugmentedLagrangianOptions& alo = options_.batch.augmented_lagrangian;
    t.constraints.set_penalty(std::min(alo.max_penalty, mu * alo.penalty_growth));
  }
  return readded;
}

double IncrementalPlanner::prepare() {
  const auto t0 = Clock::now();
  if (!tree_) return 0;
  const std::optional<graph::ISAM2Result> r = tree_->relinearize_at_estimate();
  if (r && !r->ok()) {
    spdlog::debug("iDFGP: relinearizing at the plan failed ({}); the next update rebuilds",
                  r->reason);
  }
  return seconds_since(t0);
}

Plan IncrementalPlanner::set_goal(const Goal& goal) {
  ProblemChange c;
  c.goal = goal;
  return replan(c);
}

Plan IncrementalPlanner::add_or_move_obstacle(const collision::Obstacle& obstacle) {
  ProblemChange c;
  c.add_or_move.push_back(obstacle);
  return replan(c);
}

Plan IncrementalPlanner::move_obstacle(int id, const Eigen::Isometry3d& pose) {
  const auto it = std::find_if(problem_.obstacles.begin(), problem_.obstacles.end(),
                               [id](const collision::Obstacle& o) { return o.id == id; });
  if (it == problem_.obstacles.end()) {
    return failed_plan("incremental", PlanStatus::kInvalidProblem,
                  "no obstacle with id " + std::to_string(id) + " to move");
  }
  collision::Obstacle o = *it;
  o.pose = pose;
  o.trajectory = collision::PoseTrajectory();
  return add_or_move_obstacle(o);
}

Plan IncrementalPlanner::remove_obstacle(int id) {
  ProblemChange c;
  c.remove.push_back(id);
  return replan(c);
}

Plan IncrementalPlanner::update_start(const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  ProblemChange c;
  c.start_q = q;
  c.start_qd = qd;
  return replan(c);
}

Plan IncrementalPlanner::set_horizon(double horizon) {
  ProblemChange c;
  c.horizon = horizon;
  return replan(c);
}

}  // namespace kinograph::planning

#pragma once
// iDFGP: incremental replanning (the paper's section V). The planner keeps one problem's
// planning graph in incremental form, the constraint multipliers beside it and an ISAM2 Bayes
// tree over it. A change of goal, obstacles, start state or horizon replaces exactly the
// factors of the roles it affects (a start further along the plan, at one of its knots, renames
// the states instead: shift()), and ISAM2 updates with multiplier rounds run until the
// stopping rule (stopping_rule.h) holds; the result is validated. What to do when it does not
// validate is the Replanner's policy (replanner.h).
//
// The incremental form poses the batch graph's cost function with the start (q_0, q̇_0) a stiff
// soft prior and a joint goal q_N an equality constraint instead of fixed variables (ISAM2
// cannot change a variable's value), and collision factors per obstacle. The first plan is
// BatchPlanner's own, carried over without a second solve (first_plan.h).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "kinograph/graph/isam2.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/incremental/incremental_stats.h"
#include "kinograph/planning/incremental/problem_change.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"

namespace kinograph::planning {

/// The ISAM2 settings of the incremental planner: a relinearization threshold below ISAM2's
/// general one (trajectory variables move by less than that in a replan), damping that fades
/// fast, and no linearization while the error is evaluated (prepare() linearizes at the plan).
graph::ISAM2Options default_incremental_isam2();

/// Options of IncrementalPlanner.
struct IncrementalPlannerOptions {
  /// Graph scales, penalty schedule, tolerances and validation thresholds, shared with the
  /// first plan (a batch plan) and the incremental graph's own solves.
  BatchPlannerOptions batch;
  /// ISAM2 settings (Gauss–Newton with the safeguard).
  graph::ISAM2Options isam2 = default_incremental_isam2();
  /// ISAM2 updates allowed per replan (all multiplier rounds together): bounds its latency.
  int max_updates = 40;
  /// Multiplier rounds allowed per replan.
  int max_rounds = 8;
  /// Answer with the first update whose plan validates and whose objective has settled
  /// (StoppingRule::accept); false polishes the objective to the stopping rule's end.
  bool stop_at_first_valid = true;
  /// After the first plan, one replan of the unchanged problem settles the tree at its own
  /// optimum (the batch plan stops short of it), so that later replans do not depend on where
  /// the batch solve stopped; answered when it validates and costs no more than the batch plan.
  /// It is a polish of a few updates (kSettleUpdates): a tree that does not validate by then is
  /// not near its optimum and returns to the batch plan.
  bool settle_first_plan = true;
};

struct IncrementalTree;

/// ISAM2 updates a settle (IncrementalPlannerOptions::settle_first_plan) may take: from a
/// converged batch plan the first update already validates; a tree that needs more is far from
/// its optimum and is left at the batch plan rather than spend a replan's budget on it.
inline constexpr int kSettleUpdates = 3;

/// Plans once (batch) and then replans incrementally as the problem changes. Single-threaded;
/// keep one per robot.
class IncrementalPlanner {
 public:
  explicit IncrementalPlanner(IncrementalPlannerOptions options = {});
  ~IncrementalPlanner();
  IncrementalPlanner(const IncrementalPlanner&) = delete;
  IncrementalPlanner& operator=(const IncrementalPlanner&) = delete;

  /// Plans `problem` with BatchPlanner (straight line, detours) and builds the Bayes tree at its
  /// plan from its final graph and multipliers (then settles a valid one, settle_first_plan; one
  /// that does not validate is answered as it is, the tree at it). With `warm`
  /// the outer loop runs on the incremental graph from the warm start instead, and when that
  /// does not validate the batch planner's warm start (with its restarts) is carried as above.
  /// Problems that cannot be planned come back with status "invalid_problem" (and no state is
  /// kept).
  Plan plan(const Problem& problem, const Plan* warm = nullptr);

  /// Applies `change` to the current problem and replans incrementally. Needs a previous plan
  /// (else status "no_plan"); a change that makes the problem invalid (e.g. the new goal in
  /// collision) comes back as "invalid_problem" and leaves the state as it was.
  Plan replan(const ProblemChange& change);

  /// Replans `next`, the current problem with its start `m` knots into the current plan (the
  /// robot went on along it) and the same goal, horizon and steps, on the same Bayes tree: the
  /// trajectory's variables are renamed m knots earlier, keeping their linearizations, the m
  /// states left behind leave the graph, m states at rest at the goal are added at the end, and
  /// the start, goal, changed and moving obstacles' factors are replaced (so are the factors of
  /// the last m states). Other obstacle changes are applied as by replan(). A problem
  /// shift_refusal() refuses comes back as "invalid_problem" with the state as it was.
  Plan shift(const Problem& next, int m);
  /// Why shift(next, m) cannot apply (empty when it can): no plan, the DFG formulation, other
  /// steps, horizon or goal, m outside 1..N−2, or a start farther than 0.05 (rad, rad/s) from
  /// the tree's knot m.
  std::string shift_refusal(const Problem& next, int m) const;

  /// Readies the Bayes tree for the next change: relinearizes it at the current plan and
  /// re-eliminates it there with the start and goal at its root, the work the next replan
  /// would otherwise do first. Changes no plan, only how soon the next replan answers: call it
  /// while waiting for a change (e.g. right after answering). Returns its wall time [s].
  double prepare();

  /// Shorthands for a single change.
  Plan set_goal(const Goal& goal);
  Plan add_or_move_obstacle(const collision::Obstacle& obstacle);
  Plan move_obstacle(int id, const Eigen::Isometry3d& pose);
  Plan remove_obstacle(int id);
  Plan update_start(const Eigen::VectorXd& q, const Eigen::VectorXd& qd);
  Plan set_horizon(double horizon);

  bool has_plan() const { return tree_ != nullptr; }
  /// The problem as changed so far (valid after plan()).
  const Problem& problem() const { return problem_; }
  /// The latest plan.
  const Plan& current_plan() const { return plan_; }
  const IncrementalStats& last_stats() const { return stats_; }
  const IncrementalPlannerOptions& options() const { return options_; }

 private:
  /// The batch planner's plan of `problem` (warm-started from `warm` when not null), carried
  /// into a new tree when it validates; null, with the planner as it was, when it does not
  /// validate or cannot be carried.
  std::optional<Plan> carried_batch_plan(const Problem& problem, const Plan* warm);
  /// The first plan carried from a batch solve (null: it could not be carried).
  std::optional<Plan> carry_first_plan(const Problem& problem, const Plan& batch,
                                       BatchSolution& solution);
  /// One replan of the unchanged problem after a valid first plan `plan`: its plan answers
  /// when it validates and (for a carried batch plan) costs no more; a settled tree that does
  /// not validate returns to where it was.
  void settle(Plan& plan, bool first_plan);
  /// Replaces the factors `change` affects (next: the changed problem).
  void replace_factors(const ProblemChange& change, const Problem& next,
                       const std::set<int>& changed_obstacles);
  /// replan() with at most `max_updates` ISAM2 updates.
  Plan replan_within(const ProblemChange& change, int max_updates);
  /// Runs the updates of a replan whose factors are queued (at most `max_updates`) and answers
  /// it (started at `t0`).
  Plan answer_replan(std::chrono::steady_clock::time_point t0, int max_updates);
  /// ISAM2 updates and multiplier rounds until the stopping rule holds, at most `max_updates`.
  std::optional<Plan> run_updates(double previous_cost, int max_updates, PlanStatus& status,
                                  std::string& reason);
  /// A multiplier round at the tree's estimate; returns the number of factors re-added.
  int multiplier_round(const std::vector<double>& violations, bool grow,
                       const class StoppingRule& rule);
  /// The plan at the current estimate, validated; with_stats adds its cost and worst violation.
  Plan make_plan(bool with_stats = true) const;

  IncrementalPlannerOptions options_;
  Problem problem_;
  std::unique_ptr<IncrementalTree> tree_;
  Plan plan_;
  IncrementalStats stats_;
  uint32_t retired_steps_ = 0;  // steps given to retired variables so far (shift())
};

}  // namespace kinograph::planning

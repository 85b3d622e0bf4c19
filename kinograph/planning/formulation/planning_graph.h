#pragma once
// Problem → factor graph: variables q, q̇, q̈ per state, the GP prior and collocation between
// states, limits, condensed dynamics, collision, goal and task constraints, each factor listed
// in a table by its role so that a planner can replace exactly the factors a change affects.
#include <map>
#include <memory>
#include <tuple>
#include <vector>

#include "kinograph/graph/factor_graph.h"
#include "kinograph/graph/values.h"
#include "kinograph/planning/factors/collision_factors.h"
#include "kinograph/planning/factors/constrained_factor.h"
#include "kinograph/planning/factors/dynamics_workspace.h"
#include "kinograph/planning/factors/interval_factors.h"
#include "kinograph/planning/formulation/initialization.h"
#include "kinograph/planning/interpolant.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"

namespace kinograph::planning {

/// Scales s of the constraint families (a row's violation is measured as z/s, so that one
/// penalty μ and one tolerance suit all of them).
struct GraphOptions {
  double collocation_scale = 1.0;  ///< × Δt² (position rows) and × Δt (velocity rows)
  double torque_scale = 1.0;       ///< N·m, effort limits and unactuated joints
  double limit_scale = 0.1;        ///< rad, rad/s, rad/s²
  double collision_scale = 0.03;   ///< m
  double pose_scale = 0.01;        ///< m and rad (goal pose and task constraints)
  /// Pairs farther than this (m, beyond ε) are not queried from Bullet (their hinge rows are
  /// inactive unless a multiplier reaches that far, which needs λ·s/μ above the margin).
  double collision_query_margin = 0.03;
};

/// What a factor of a planning graph stands for; a change of the problem replaces the factors
/// of the roles it affects.
enum class FactorRole {
  kStart,        ///< prior on (q_0, q̇_0) (incremental form; the batch form fixes them)
  kGoal,         ///< joint goal on q_N (incremental form) or pose goal (both forms)
  kGpPrior,      ///< GP prior of interval k (depends on Δt)
  kCollocation,  ///< collocation of interval k's actuated joints (depends on Δt)
  kInterval,     ///< interval k's dynamics between the knots: shooting defect, interior limits
  kLimits,       ///< q, q̇, q̈ limits of state k
  kDynamics,     ///< equations of motion and torque rows of state k
  kCollision,    ///< hinges of state k (sub-step s) against one obstacle or all of them
  kTask,         ///< a task constraint at state k
  /// hinges of state k (sub-step s) between the robot's own links and against the floor:
  /// unchanged by obstacle changes, so replans keep them
  kSelfCollision,
};

/// Names one factor of a planning graph, stable across rebuilds and replans (so constraint
/// multipliers can be carried to a replacement).
struct FactorKey {
  FactorRole role = FactorRole::kGoal;
  int step = 0;    ///< state or interval k
  int sub = 0;     ///< collision: sub-step 0..substeps; dynamics (DFG): equation index
  int index = -1;  ///< collision: obstacle id (−1: all obstacles); task: its index

  bool operator<(const FactorKey& o) const {
    return std::tie(role, step, sub, index) < std::tie(o.role, o.step, o.sub, o.index);
  }
  bool operator==(const FactorKey& o) const {
    return role == o.role && step == o.step && sub == o.sub && index == o.index;
  }
  /// Whether the factor depends on the time step Δt (replaced when the horizon changes).
  bool depends_on_dt() const {
    return role == FactorRole::kGpPrior || role == FactorRole::kCollocation ||
           role == FactorRole::kInterval || role == FactorRole::kCollision ||
           role == FactorRole::kSelfCollision;
  }
};

/// One factor of the table.
struct FactorEntry {
  graph::FactorPtr factor;
  /// The same factor when it is a ConstrainedFactor (soft and constraint rows), else null.
  std::shared_ptr<ConstrainedFactor> constrained;
  FactorKey key;
  /// The factor anchors a fixed variable's value (start, joint goal): batch solves fix the
  /// variable instead and leave the factor out; incremental solves free the variable.
  bool anchor = false;
  size_t slot = 0;  ///< index in the solver's factor graph
};

/// The two layouts of one problem's graph. Both pose the same cost function.
enum class GraphForm {
  /// Start and joint goal fixed variables, one collision factor per state for all obstacles.
  kBatch,
  /// Start and joint goal as anchor factors, collision factors per obstacle (an obstacle
  /// change then replaces only its own factors).
  kIncremental,
};

/// Which between-knot rows (IntervalDynamicsFactor, docs/interpolation.md) a graph holds. The
/// batch planner solves the knot-only graph first and adds these where the interpolant needs
/// them; every other graph holds all of them (the default).
struct IntervalRows {
  /// No interval factors: every joint on the collocation cubic and limits at the knots only
  /// (unactuated joints then follow the cubic too, so the plan holds only at its knots).
  bool knots_only = false;
  /// Per interval, which interior limit rows it holds (IntervalLimitRows bits); empty = all of
  /// them on every interval. Intervals without any keep the unactuated joints' shooting defect.
  std::vector<char> limits;
  /// Longest RK4 step (s) of the interval factors: the interpolant's, or longer for the batch
  /// planner's coarse warm-up solve before the rows on the interpolant itself.
  double integration_step = kMaxIntegrationStep;
};

/// A built planning graph: the role table, the factor graph of its non-anchor factors, the
/// variables and the shared workspaces.
struct PlanningGraph {
  std::vector<FactorEntry> entries;
  graph::FactorGraph graph;  ///< every non-anchor entry, at its slot
  graph::Values values;
  std::shared_ptr<DynamicsWorkspace> dynamics_workspace;
  /// Collision worlds by obstacle id; the batch form's one world of all obstacles is under −1.
  std::map<int, std::shared_ptr<CollisionContext>> collision;
  GraphForm form = GraphForm::kBatch;
  int steps = 0;
  int nq = 0;

  /// Appends an entry (non-anchors also to `graph`, setting the entry's slot).
  void add(FactorEntry entry);
  /// The entries whose constraint rows the augmented Lagrangian tracks (non-anchors only when
  /// `with_anchors` is false).
  std::vector<const FactorEntry*> constraints(bool with_anchors) const;
};

/// Builds the condensed formulation (τ eliminated into per-step dynamics factors) with its
/// variables initialized to `init`; the start state is fixed, and so is the goal state (joint
/// goal) or its velocity and acceleration (pose goal). Throws std::invalid_argument or
/// std::out_of_range for inconsistent input (sizes, unknown frames, repeated obstacle ids).
PlanningGraph build_graph(const Problem& problem, const Trajectory& init,
                          const GraphOptions& options = {}, GraphForm form = GraphForm::kBatch,
                          const IntervalRows& between = {});

/// An entry for a constraint factor (or, make_soft_entry, a plain one) under `key`.
FactorEntry make_entry(std::shared_ptr<ConstrainedFactor> factor, FactorKey key);
FactorEntry make_soft_entry(graph::FactorPtr soft_factor, FactorKey key);

/// The GP prior, collocation and between-knot dynamics (those of `between`) of every interval
/// for the problem's Δt, interval by interval. Throws std::invalid_argument if `between.limits`
/// is neither empty nor one entry per interval.
std::vector<FactorEntry> timing_entries(const Problem& problem, const GraphOptions& options,
                                        const IntervalRows& between = {});
/// The collision hinges of every free state and sub-step against the obstacles of `context`,
/// keyed by `obstacle` (an id, or −1 for a context of all obstacles).
std::vector<FactorEntry> collision_entries(const Problem& problem,
                                           const std::shared_ptr<CollisionContext>& context,
                                           int obstacle, const GraphOptions& options);
/// The self-collision and floor hinges of every free state from `first` on and the sub-steps
/// of the intervals ending there (role kSelfCollision, in a collision world of their own); none
/// when the problem has neither.
std::vector<FactorEntry> self_collision_entries(const Problem& problem,
                                                const GraphOptions& options, int first = 0);
/// The incremental form's entries on the states from `first` (≥ 1) on and on the intervals
/// ending there: GP prior, collocation, between-knot dynamics, limits, dynamics, self-collision,
/// task constraints and the hinges against each obstacle of `obstacles` (by id); not the start
/// or the goal. What a trajectory needs for the states it gains at its end.
/// Throws std::invalid_argument for `first` outside 1..steps.
std::vector<FactorEntry> tail_entries(
    const Problem& problem, int first, const std::shared_ptr<DynamicsWorkspace>& workspace,
    const std::map<int, std::shared_ptr<CollisionContext>>& obstacles,
    const GraphOptions& options);
/// A collision world of `obstacles` with the problem's query distance.
std::shared_ptr<CollisionContext> collision_context(
    const Problem& problem, const std::vector<collision::Obstacle>& obstacles,
    const GraphOptions& options);
/// The start prior (incremental form): a stiff soft term on (q_0, q̇_0).
FactorEntry start_entry(const Problem& problem);
/// The goal: equality rows on q_N (joint goal, an anchor) or the pose goal's factor.
FactorEntry goal_entry(const Problem& problem, const std::shared_ptr<DynamicsWorkspace>& workspace,
                       const GraphOptions& options);

/// The soft part of the cost (constraint rows left out) and, with `violation`, the largest
/// constraint violation in the rows' own units, over `entries` (anchors included).
double soft_cost(const std::vector<FactorEntry>& entries, const graph::Values& values,
                 double* violation = nullptr);
/// The same over entries given by pointer, in their order.
double soft_cost(const std::vector<const FactorEntry*>& entries, const graph::Values& values,
                 double* violation = nullptr);

/// Reads q, q̇, q̈ of every state back from the values.
Trajectory read_trajectory(const graph::Values& values, int steps, int nq);

/// A plan of `trajectory`: its states, the step times, and τ from inverse dynamics (exact for the
/// condensed formulation, which eliminates τ). Stats and validation are left empty.
Plan plan_from_trajectory(const Problem& problem, const Trajectory& trajectory);

}  // namespace kinograph::planning

#pragma once
// Problem → factor graph: variables q, q̇, q̈ per state, the GP prior and collocation between
// states, limits, condensed dynamics, collision, pose goal and task constraints.
#include <memory>
#include <vector>

#include "kinograph/graph/factor_graph.h"
#include "kinograph/graph/values.h"
#include "kinograph/planning/factors/collision_factors.h"
#include "kinograph/planning/factors/constrained_factor.h"
#include "kinograph/planning/formulation/initialization.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"

namespace kinograph::planning {

/// Scales s of the constraint families (a row's violation is measured as z/s, so that one
/// penalty μ and one tolerance suit all of them). Defaults chosen on the shipped scenes.
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

/// A built planning graph with its variables and the handles the planner needs.
struct PlanningGraph {
  graph::FactorGraph graph;
  graph::Values values;
  /// Every factor with constraint rows (the augmented Lagrangian's multipliers live there).
  std::vector<std::shared_ptr<ConstrainedFactor>> constraints;
  std::shared_ptr<dynamics::Data> dynamics_workspace;
  std::shared_ptr<CollisionContext> collision;  ///< null without obstacles
  int steps = 0;
  int nq = 0;
};

/// Builds the condensed formulation (τ eliminated into per-step dynamics factors) with its
/// variables initialized to `init`; the start state is fixed, and so is the goal state (joint
/// goal) or its velocity and acceleration (pose goal). Throws std::invalid_argument or
/// std::out_of_range for inconsistent input (sizes, unknown frames, repeated obstacle ids).
PlanningGraph build_graph(const Problem& problem, const Trajectory& init,
                          const GraphOptions& options = {});

/// Reads q, q̇, q̈ of every state back from the values.
Trajectory read_trajectory(const graph::Values& values, int steps, int nq);

/// A plan of `trajectory`: its states, the step times, and τ from inverse dynamics (exact for the
/// condensed formulation, which eliminates τ). Stats and validation are left empty.
Plan plan_from_trajectory(const Problem& problem, const Trajectory& trajectory);

}  // namespace kinograph::planning

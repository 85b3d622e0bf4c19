#include "kinograph/planning/solver/violation_text.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "kinograph/planning/factors/collision_factors.h"
#include "kinograph/planning/factors/dynamics_factors.h"
#include "kinograph/planning/factors/pose_factors.h"
#include "kinograph/planning/factors/state_target_factor.h"
#include "kinograph/planning/factors/trajectory_factors.h"
#include "kinograph/planning/formulation/dfg_builder.h"
#include "kinograph/planning/user_terms.h"

namespace kinograph::planning {
namespace {

const char* kQuantity[] = {"position", "velocity", "acceleration", "torque"};

// A q, q̇, q̈ (derivative 0..2) or τ (3) row of `joint` with raw value z against the user's
// limit; past the planner's tightened bound but inside the limit, says so.
std::string limit_text(const dynamics::Model& model, int derivative, int joint, double z,
                       const RowSpec& row, double violation, double t) {
  const dynamics::JointLimits& l = model.bodies[joint].limits;
  const double symmetric[] = {0, l.velocity, l.acceleration, l.effort};
  const double lo = derivative == 0 ? l.lower : -symmetric[derivative];
  const double hi = derivative == 0 ? l.upper : symmetric[derivative];
  const std::string u = joint_unit(model, joint, derivative);
  const std::string head =
      joint_label(model, joint) + " " + kQuantity[derivative] + " " + number(z) + " " + u;
  const double over = std::max(lo - z, z - hi);
  const std::string limit = derivative == 0
                                ? "its limits [" + number(lo) + ", " + number(hi) + "] " + u
                                : "its " + number(hi) + " " + u + " limit";
  if (over > 0) {
    return head + (derivative == 0 ? " is outside " : " exceeds ") + limit + " by " + number(over) +
           " " + u + " at " + at_time(t);
  }
  const double bound = z > 0 ? row.upper : row.lower;
  return head + " is within " + limit + " but past the planner's margin (bound " + number(bound) +
         " " + u + ") by " + number(violation) + " " + u + " at " + at_time(t);
}

std::string collision_text(const CollisionFactor& f, int row, double z, const RowSpec& spec) {
  const CollisionContext& ctx = f.context();
  for (size_t g = 0; g < ctx.row_of.size(); ++g) {
    for (size_t slot = 0; slot < ctx.row_of[g].size(); ++slot) {
      if (ctx.row_of[g][slot] != row) continue;
      // row_of is indexed by the model's collision geometry.
      const std::string& link = ctx.model->collision[g].link_name;
      const std::string obstacle = "obstacle " + std::to_string(ctx.obstacle_ids[slot]);
      if (z < 0) {
        return "link '" + link + "' penetrates " + obstacle + " by " + number(-z) + " m at " +
               at_time(f.time());
      }
      return "link '" + link + "' is " + number(z) + " m from " + obstacle + " at " +
             at_time(f.time()) + ", inside the planner's " + number(spec.lower) +
             " m safety distance";
    }
  }
  return "collision at " + at_time(f.time()) + ": clearance " + number(z) + " m";
}

const char* kind_name(char kind) {
  switch (kind) {
    case 'q':
      return "position";
    case 'v':
      return "velocity";
    case 'a':
      return "acceleration";
    default:
      return "value";
  }
}

const char* role_name(FactorRole role) {
  switch (role) {
    case FactorRole::kStart:
      return "start";
    case FactorRole::kGoal:
      return "goal";
    case FactorRole::kGpPrior:
      return "smoothness prior";
    case FactorRole::kCollocation:
      return "collocation";
    case FactorRole::kLimits:
      return "limits";
    case FactorRole::kDynamics:
      return "equations of motion";
    case FactorRole::kCollision:
      return "collision";
    case FactorRole::kTask:
      return "task constraint";
  }
  return "constraint";
}

}  // namespace

std::string describe_violation(const Problem& problem, const ConstraintReport& worst) {
  if (worst.entry == nullptr || worst.row < 0 || !worst.entry->constrained || !problem.model) {
    return worst.where.empty() ? "all constraints hold" : worst.where;
  }
  const FactorEntry& e = *worst.entry;
  const ConstrainedFactor& f = *e.constrained;
  const RowSpec& row = f.rows()[worst.row];
  const dynamics::Model& model = *problem.model;
  const double dt = problem.dt(), t = e.key.step * dt, z = worst.value;
  if (const auto* lim = dynamic_cast<const StateLimitFactor*>(&f)) {
    const StateLimitFactor::Limit& l = lim->limits()[worst.row];
    return limit_text(model, l.variable, l.joint, z, row, worst.violation, t);
  }
  const auto torque_text = [&](int j) {
    if (row.kind == RowKind::kEquality) {
      return joint_label(model, j) + " is unactuated but needs " + number(z) + " " +
             joint_unit(model, j, 3) + " at " + at_time(t);
    }
    return limit_text(model, 3, j, z, row, worst.violation, t);
  };
  if (const auto* dyn = dynamic_cast<const DynamicsStepFactor*>(&f)) {
    return torque_text(dyn->joint_of_row()[worst.row]);
  }
  if (dynamic_cast<const DfgTorqueRowsFactor*>(&f) != nullptr) {
    // The same rows as the condensed factor's; their constraint rows come first and do not
    // depend on the margins or the soft weight.
    std::vector<int> joints;
    DynamicsStepFactor::rows_for(model, DynamicsStepOptions{}, &joints);
    if (worst.row < static_cast<int>(joints.size())) return torque_text(joints[worst.row]);
  }
  if (const auto* col = dynamic_cast<const CollisionFactor*>(&f)) {
    return collision_text(*col, worst.row, z, row);
  }
  if (const auto* c = dynamic_cast<const CollocationFactor*>(&f)) {
    const int n = c->joints(), j = worst.row % n, derivative = worst.row < n ? 0 : 1;
    return joint_label(model, j) + " " + kQuantity[derivative] + " between " + at_time(t) +
           " and " + number(t + dt) + " s disagrees with its " +
           (derivative == 0 ? "velocity and acceleration" : "acceleration") + " by " +
           number(worst.violation) + " " + joint_unit(model, j, derivative);
  }
  if (const auto* pose = dynamic_cast<const PoseFactor*>(&f)) {
    const bool rotation = pose->orientation_row(worst.row);
    const std::string off = rotation ? number(worst.violation) + " (sine of the angle)"
                                     : number(worst.violation) + " m";
    const std::string what = rotation ? "orientation" : "position";
    if (e.key.role == FactorRole::kTask) {
      return "task constraint " + std::to_string(e.key.index + 1) + " on frame '" +
             pose->frame_name() + "' is off in " + what + " by " + off + " at " + at_time(t);
    }
    return "frame '" + pose->frame_name() + "' misses its goal " + what + " by " + off + " at " +
           at_time(t);
  }
  if (const auto* target = dynamic_cast<const StateTargetFactor*>(&f)) {
    const int n = model.nq(), j = worst.row % n;
    const graph::Key key = target->keys()[static_cast<size_t>(worst.row / n)];
    const int derivative = key.kind() == 'v' ? 1 : key.kind() == 'a' ? 2 : 0;
    const std::string u = joint_unit(model, j, derivative);
    return joint_label(model, j) + " " + kind_name(key.kind()) + " is " + number(z) + " " + u +
           ", " + number(worst.violation) + " " + u + " from its " + role_name(e.key.role) + " " +
           number(row.lower) + " " + u + " at " + at_time(key.step() * dt);
  }
  // The DFG's equations and torque rows: the role and time, with the factor for the specialist.
  return std::string(role_name(e.key.role)) + " at " + at_time(t) + " off by " +
         number(worst.violation) + " (" + worst.where + ")";
}

std::string infeasible_reason(const Problem& problem, const OuterLoopResult& result) {
  std::ostringstream os;
  os << "constraints still violated after " << result.outer_iterations << " outer and "
     << result.iterations
     << " LM iterations; the worst: " << describe_violation(problem, result.worst);
  return os.str();
}

}  // namespace kinograph::planning

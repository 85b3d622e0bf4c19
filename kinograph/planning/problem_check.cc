#include "kinograph/planning/problem_check.h"

#include <cmath>
#include <memory>
#include <sstream>

#include "kinograph/collision/collision_world.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/clearance_world.h"
#include "kinograph/planning/motion_bounds.h"
#include "kinograph/planning/user_terms.h"

namespace kinograph::planning {
namespace {

std::string joint_list_outside(const dynamics::Model& model, const Eigen::VectorXd& q,
                               const char* what) {
  std::ostringstream os;
  for (int j = 0; j < model.nq(); ++j) {
    const auto& l = model.bodies[j].limits;
    if (q[j] < l.lower || q[j] > l.upper) {
      const std::string u = joint_unit(model, j, 0);
      os << what << " " << joint_label(model, j) << " = " << number(q[j]) << " " << u
         << " is outside its limits [" << number(l.lower) << ", " << number(l.upper) << "] " << u
         << "; ";
    }
  }
  return os.str();
}

// The start velocity within the limits, and able to stop before a position limit.
std::string check_start_velocity(const dynamics::Model& model, const Eigen::VectorXd& q0,
                                 const Eigen::VectorXd& v0) {
  for (int j = 0; j < model.nq(); ++j) {
    const dynamics::JointLimits& l = model.bodies[j].limits;
    const std::string u = joint_unit(model, j, 0), uv = joint_unit(model, j, 1);
    if (std::abs(v0[j]) > l.velocity) {
      return joint_label(model, j) + " starts at " + number(v0[j]) + " " + uv +
             ", beyond its velocity limit " + number(l.velocity) + " " + uv;
    }
    const double stop = stopping_distance(v0[j], l.acceleration);
    const double room = v0[j] > 0 ? l.upper - q0[j] : q0[j] - l.lower;
    if (v0[j] != 0 && stop > room) {
      return joint_label(model, j) + " starts at " + number(v0[j]) + " " + uv + " and needs " +
             number(stop) + " " + u + " to stop within its acceleration limit " +
             number(l.acceleration) + " " + joint_unit(model, j, 2) + ", but its " +
             (v0[j] > 0 ? "upper" : "lower") + " position limit is " + number(room) + " " + u +
             " away";
    }
  }
  return "";
}

// The horizon at least the time each joint needs alone under its velocity and acceleration
// limits (a true lower bound: coupling and torque limits only make a motion slower).
std::string check_horizon(const Problem& p) {
  if (p.goal.kind != Goal::Kind::kJoint) return "";
  const dynamics::Model& model = *p.model;
  for (int j = 0; j < model.nq(); ++j) {
    const dynamics::JointLimits& l = model.bodies[j].limits;
    const double v0 = p.start_qd.size() == model.nq() ? p.start_qd[j] : 0.0;
    const double d = p.goal.q[j] - p.start_q[j];
    const double t = min_time_to_rest(d, v0, l.velocity, l.acceleration);
    // Relative slack for the rounding of the closed form only; a horizon at the bound passes.
    if (!(t > p.horizon * (1 + 1e-9))) continue;
    const std::string u = joint_unit(model, j, 0), uv = joint_unit(model, j, 1);
    std::string why = joint_label(model, j) + " must move " + number(std::abs(d)) + " " + u;
    if (v0 != 0) why += " from " + number(v0) + " " + uv;
    if (l.velocity == 0) return why + " but its velocity limit is 0";
    const auto [needs, horizon] = distinct_numbers(t, p.horizon);
    why += " and needs " + needs + " s at its velocity limit " + number(l.velocity) + " " + uv;
    if (std::isfinite(l.acceleration)) {
      why += " and acceleration limit " + number(l.acceleration) + " " + joint_unit(model, j, 2);
    }
    return why + "; the horizon is " + horizon + " s";
  }
  return "";
}

// At the goal the robot rests, so each joint must hold the gravity torque there: an unactuated
// joint none, an actuated one within its effort. The margin covers how far a plan may end from
// the goal at rest and still validate (5× the validator's default 0.01 goal and final-velocity
// tolerances, through the torque's first derivatives, doubled), so only sure cases are refused.
std::string check_goal_holding(const Problem& p) {
  if (p.goal.kind != Goal::Kind::kJoint) return "";
  const dynamics::Model& model = *p.model;
  const int n = model.nq();
  dynamics::Data data(model);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  dynamics::rnea_derivatives(model, data, p.goal.q, zero, zero);
  constexpr double kSlack = 0.05;
  for (int j = 0; j < n; ++j) {
    const double tau = data.tau[j];
    const double margin =
        2 * kSlack *
            (data.dtau_dq.row(j).cwiseAbs().sum() + data.M.row(j).cwiseAbs().sum() +
             data.dtau_dqd.row(j).cwiseAbs().sum()) +
        2e-3;
    const dynamics::Body& b = model.bodies[j];
    const std::string u = joint_unit(model, j, 3);
    if (!b.actuated && std::abs(tau) > margin) {
      return "at the goal the robot is at rest, and " + joint_label(model, j) +
             " is unactuated but would have to hold " + number(tau) + " " + u + " against gravity";
    }
    if (b.actuated && std::abs(tau) > b.limits.effort + margin) {
      return "at the goal the robot is at rest, and " + joint_label(model, j) + " needs " +
             number(tau) + " " + u + " to hold it against gravity, over its " +
             number(b.limits.effort) + " " + u + " effort limit";
    }
  }
  return "";
}

// A goal's tolerances must be finite and non-negative (0: the validator's default), one per
// joint for a joint goal.
std::string check_goal_tolerance(const Problem& p) {
  const Goal& g = p.goal;
  const dynamics::Model& model = *p.model;
  if (g.joint_tolerance.size() != 0) {
    if (g.kind != Goal::Kind::kJoint) return "a pose goal takes no joint tolerances";
    if (g.joint_tolerance.size() != model.nq()) return "joint goal tolerance has the wrong size";
    for (int j = 0; j < model.nq(); ++j) {
      if (!(g.joint_tolerance[j] >= 0) || !std::isfinite(g.joint_tolerance[j]))
        return "the goal tolerance of " + joint_label(model, j) + " must be a number >= 0";
    }
  }
  for (const double t : {g.position_tolerance, g.orientation_tolerance}) {
    if (!(t >= 0) || !std::isfinite(t))
      return "the goal's position and orientation tolerances must be numbers >= 0";
  }
  return "";
}

// Why configuration q (the start or the goal) is in collision, naming the pair and the depth;
// empty when it is clear of obstacles, the floor and its own links (`world`: the problem's
// clearance world, `data` a workspace of its model).
std::string collision_at(const Problem& problem, collision::CollisionWorld& world,
                         dynamics::Data& data, const Eigen::VectorXd& q, const char* what) {
  dynamics::forward_kinematics(*problem.model, data, q);
  const collision::Proximity p = world.closest(data, 0);
  if (!(p.distance < 0)) return "";
  std::ostringstream os;
  os << "the " << what << " configuration is in collision: " << describe_pair(*problem.model, p)
     << " overlap by " << -p.distance << " m";
  return os.str();
}

}  // namespace

std::string check_problem(const Problem& p) {
  if (!p.model) return "problem has no robot model";
  const dynamics::Model& model = *p.model;
  const int n = model.nq();
  if (p.steps < 1) return "steps must be at least 1";
  if (!(p.horizon > 0) || !std::isfinite(p.horizon)) return "horizon must be positive and finite";
  if (p.start_q.size() != n)
    return "start_q has " + std::to_string(p.start_q.size()) + " entries, the robot has " +
           std::to_string(n) + " joints";
  if (p.start_qd.size() != 0 && p.start_qd.size() != n) return "start_qd has the wrong size";
  if (!p.start_q.allFinite() || !p.start_qd.allFinite()) return "start state holds NaN or inf";
  if (!(p.objectives.qc > 0) || !std::isfinite(p.objectives.qc)) return "Qc must be positive";
  if (!(p.objectives.min_torque >= 0) || !(p.objectives.collision_epsilon >= 0) ||
      !(p.objectives.self_collision_epsilon >= 0) || !(p.objectives.limit_epsilon >= 0))
    return "objective weights and margins must be non-negative numbers";
  std::string r = joint_list_outside(model, p.start_q, "start");
  if (!r.empty()) return r;
  if (p.start_qd.size() == n) {
    r = check_start_velocity(model, p.start_q, p.start_qd);
    if (!r.empty()) return r;
  }
  if (p.goal.kind == Goal::Kind::kJoint) {
    if (p.goal.q.size() != n) return "joint goal has the wrong size";
    if (!p.goal.q.allFinite()) return "joint goal holds NaN or inf";
    r = joint_list_outside(model, p.goal.q, "goal");
    if (!r.empty()) return r;
  } else {
    if (!p.goal.pose.matrix().allFinite()) return "goal pose holds NaN or inf";
    try {
      model.frame_index(p.goal.frame);
    } catch (const std::out_of_range&) {
      return "goal frame '" + p.goal.frame + "' is not in the model";
    }
  }
  r = check_goal_tolerance(p);
  if (!r.empty()) return r;
  r = check_horizon(p);
  if (!r.empty()) return r;
  r = check_goal_holding(p);
  if (!r.empty()) return r;
  for (const auto& t : p.task_constraints) {
    try {
      model.frame_index(t.frame);
    } catch (const std::out_of_range&) {
      return "task-constraint frame '" + t.frame + "' is not in the model";
    }
  }
  if (has_clearance_checks(p)) {
    try {
      // One world for both: a replan checks its problem on the way to every answer.
      const std::unique_ptr<collision::CollisionWorld> world = clearance_world(p);
      dynamics::Data data(model);
      r = collision_at(p, *world, data, p.start_q, "start");
      if (r.empty() && p.goal.kind == Goal::Kind::kJoint) {
        r = collision_at(p, *world, data, p.goal.q, "goal");
      }
      if (!r.empty()) return r;
    } catch (const std::exception& e) {
      return std::string("bad obstacle: ") + e.what();
    }
  }
  return "";
}

}  // namespace kinograph::planning

#include "kinograph/planning/problem_check.h"

#include <cmath>
#include <memory>
#include <sstream>

#include "kinograph/collision/collision_world.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/clearance_world.h"

namespace kinograph::planning {
namespace {

std::string joint_list_outside(const dynamics::Model& model, const Eigen::VectorXd& q,
                               const char* what) {
  std::ostringstream os;
  for (int j = 0; j < model.nq(); ++j) {
    const auto& l = model.bodies[j].limits;
    if (q[j] < l.lower || q[j] > l.upper) {
      os << what << " joint '" << model.bodies[j].joint_name << "' = " << q[j] << " is outside ["
         << l.lower << ", " << l.upper << "]; ";
    }
  }
  return os.str();
}

// Why configuration q (the start or the goal) is in collision, naming the pair and the depth;
// empty when it is clear of obstacles, the floor and its own links.
std::string collision_at(const Problem& problem, const Eigen::VectorXd& q, const char* what) {
  const std::unique_ptr<collision::CollisionWorld> world = clearance_world(problem);
  dynamics::Data data(*problem.model);
  dynamics::forward_kinematics(*problem.model, data, q);
  const collision::Proximity p = world->closest(data, 0);
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
  for (const auto& t : p.task_constraints) {
    try {
      model.frame_index(t.frame);
    } catch (const std::out_of_range&) {
      return "task-constraint frame '" + t.frame + "' is not in the model";
    }
  }
  if (has_clearance_checks(p)) {
    try {
      r = collision_at(p, p.start_q, "start");
      if (r.empty() && p.goal.kind == Goal::Kind::kJoint) r = collision_at(p, p.goal.q, "goal");
      if (!r.empty()) return r;
    } catch (const std::exception& e) {
      return std::string("bad obstacle: ") + e.what();
    }
  }
  return "";
}

}  // namespace kinograph::planning

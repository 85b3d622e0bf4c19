#include "kinograph/lcm/message_convert.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <unordered_map>

namespace kinograph::messages {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

template <class It>
bool all_finite(It begin, It end) {
  return std::all_of(begin, end, [](double v) { return std::isfinite(v); });
}

// A quaternion (w, x, y, z) from the wire must be finite and near unit length; a small drift
// from serialization is normalized away, anything else is a sender's bug worth reporting.
Check quaternion_from(const double* wxyz, const std::string& field, Eigen::Quaterniond& q) {
  if (!all_finite(wxyz, wxyz + 4)) return Check::fail(field + " is not finite");
  q = Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  const double norm = q.norm();
  if (std::abs(norm - 1.0) > 1e-3) {
    return Check::fail(field + " is not a unit quaternion (norm " + std::to_string(norm) + ")");
  }
  q.normalize();
  return {};
}

Check robot_field(const std::string& robot, const RobotIdentity& identity,
                  const std::string& type) {
  if (identity.matches(robot)) return {};
  return Check::fail(type + ".robot is \"" + robot + "\", this planner serves \"" +
                     identity.model_name + "\"");
}

}  // namespace

bool RobotIdentity::matches(const std::string& robot) const {
  if (robot.empty()) return true;
  const std::string r = lower(robot);
  return r == lower(model_name) || r == lower(channel_prefix);
}

Check goal_from_message(const goal_t& msg, const dynamics::Model& model,
                        const RobotIdentity& identity, GoalRequest& out) {
  if (Check c = robot_field(msg.robot, identity, "goal_t"); !c.ok) return c;
  if (msg.goal_id < 0) return Check::fail("goal_t.goal_id must be >= 0");
  if (!std::isfinite(msg.duration_s) || msg.duration_s < 0 || msg.duration_s > 3600) {
    return Check::fail("goal_t.duration_s must be in [0, 3600] s (0 = default horizon)");
  }
  GoalRequest request;
  request.goal_id = msg.goal_id;
  request.utime = msg.utime;
  request.duration_s = msg.duration_s;
  if (msg.kind == goal_t::KIND_JOINT_CONFIGURATION) {
    if (msg.num_joints != model.nq()) {
      return Check::fail("goal_t.num_joints is " + std::to_string(msg.num_joints) + ", robot " +
                         model.name + " has " + std::to_string(model.nq()) + " joints");
    }
    if (!all_finite(msg.joint_position.begin(), msg.joint_position.end())) {
      return Check::fail("goal_t.joint_position is not finite");
    }
    request.goal.kind = planning::Goal::Kind::kJoint;
    request.goal.q = Eigen::Map<const Eigen::VectorXd>(msg.joint_position.data(), model.nq());
  } else if (msg.kind == goal_t::KIND_END_EFFECTOR_POSE) {
    const auto& frames = model.frames;
    const bool known = std::any_of(frames.begin(), frames.end(),
                                   [&](const auto& f) { return f.name == msg.ee_frame; });
    if (!known) return Check::fail("goal_t.ee_frame \"" + msg.ee_frame + "\" is not a frame");
    if (!all_finite(msg.ee_position, msg.ee_position + 3)) {
      return Check::fail("goal_t.ee_position is not finite");
    }
    Eigen::Quaterniond rotation;
    if (Check c = quaternion_from(msg.ee_quaternion, "goal_t.ee_quaternion", rotation); !c.ok) {
      return c;
    }
    request.goal.kind = planning::Goal::Kind::kPose;
    request.goal.frame = msg.ee_frame;
    request.goal.pose =
        Eigen::Translation3d(msg.ee_position[0], msg.ee_position[1], msg.ee_position[2]) * rotation;
  } else {
    return Check::fail("goal_t.kind " + std::to_string(msg.kind) + " is unknown");
  }
  out = std::move(request);
  return {};
}

Check obstacles_from_message(const obstacle_list_t& msg, std::vector<ObstacleUpdate>& out) {
  if (msg.obstacles.size() > static_cast<size_t>(kMaxObstaclesPerMessage)) {
    return Check::fail("obstacle_list_t.num_obstacles is " + std::to_string(msg.obstacles.size()) +
                       ", more than the " + std::to_string(kMaxObstaclesPerMessage) +
                       " one message may carry");
  }
  std::vector<ObstacleUpdate> updates;
  updates.reserve(msg.obstacles.size());
  for (size_t i = 0; i < msg.obstacles.size(); ++i) {
    const obstacle_t& o = msg.obstacles[i];
    const std::string field = "obstacle_list_t.obstacles[" + std::to_string(i) + "]";
    if (o.id.empty()) return Check::fail(field + ".id is empty");
    ObstacleUpdate u;
    u.id = o.id;
    if (o.action == obstacle_t::REMOVE) {
      u.remove = true;
      updates.push_back(std::move(u));
      continue;
    }
    if (o.action != obstacle_t::ADD_OR_MOVE) {
      return Check::fail(field + ".action " + std::to_string(o.action) + " is unknown");
    }
    const std::string named = field + " (\"" + o.id + "\")";
    if (!all_finite(o.size, o.size + 3) || !all_finite(o.position, o.position + 3)) {
      return Check::fail(named + " has a non-finite size or position");
    }
    const double a = o.size[0], b = o.size[1], c = o.size[2];
    switch (o.shape) {
      case obstacle_t::BOX:
        u.shape = collision::Shape::box(a, b, c);
        break;
      case obstacle_t::SPHERE:
        u.shape = collision::Shape::sphere(a);
        break;
      case obstacle_t::CYLINDER:
        u.shape = collision::Shape::cylinder(a, b);
        break;
      case obstacle_t::CAPSULE:
        u.shape = collision::Shape::capsule(a, b);
        break;
      default:
        return Check::fail(field + ".shape " + std::to_string(o.shape) + " is unknown");
    }
    if (std::string e = collision::range_error(u.shape); !e.empty()) {
      return Check::fail(named + ".size: " + e);
    }
    const Eigen::Vector3d position(o.position[0], o.position[1], o.position[2]);
    if (std::string e = collision::position_range_error(position); !e.empty()) {
      return Check::fail(named + ": " + e);
    }
    Eigen::Quaterniond rotation;
    if (Check ch = quaternion_from(o.quaternion, field + ".quaternion", rotation); !ch.ok) {
      return ch;
    }
    u.pose = Eigen::Translation3d(o.position[0], o.position[1], o.position[2]) * rotation;
    updates.push_back(std::move(u));
  }
  out = std::move(updates);
  return {};
}

namespace {

// Model index of each entry of a message's joint_name list, which may be in any order but must
// name every joint of the model once.
Check joint_indices(const std::vector<std::string>& names, const dynamics::Model& model,
                    const std::string& type, std::vector<int>& out) {
  const int n = model.nq();
  std::unordered_map<std::string, int> index;
  for (int j = 0; j < n; ++j) index[model.bodies[j].joint_name] = j;
  std::vector<bool> seen(n, false);
  std::vector<int> indices(names.size());
  for (size_t i = 0; i < names.size(); ++i) {
    auto it = index.find(names[i]);
    if (it == index.end()) {
      return Check::fail(type + ".joint_name[" + std::to_string(i) + "] \"" + names[i] +
                         "\" is not a joint of " + model.name);
    }
    if (seen[it->second]) {
      return Check::fail(type + ".joint_name \"" + names[i] + "\" appears twice");
    }
    seen[it->second] = true;
    indices[i] = it->second;
  }
  out = std::move(indices);
  return {};
}

Check joint_count(int32_t count, const dynamics::Model& model, const std::string& type) {
  if (count == model.nq()) return {};
  return Check::fail(type + ".num_joints is " + std::to_string(count) + ", robot " + model.name +
                     " has " + std::to_string(model.nq()) + " joints");
}

}  // namespace

Check state_from_message(const robot_state_t& msg, const dynamics::Model& model,
                         const RobotIdentity& identity, MeasuredState& out) {
  if (Check c = robot_field(msg.robot, identity, "robot_state_t"); !c.ok) return c;
  if (Check c = joint_count(msg.num_joints, model, "robot_state_t"); !c.ok) return c;
  if (!all_finite(msg.position.begin(), msg.position.end()) ||
      !all_finite(msg.velocity.begin(), msg.velocity.end())) {
    return Check::fail("robot_state_t.position or velocity is not finite");
  }
  std::vector<int> index;
  if (Check c = joint_indices(msg.joint_name, model, "robot_state_t", index); !c.ok) return c;
  MeasuredState state;
  state.utime = msg.utime;
  state.q.setZero(model.nq());
  state.qd.setZero(model.nq());
  for (size_t i = 0; i < index.size(); ++i) {
    state.q[index[i]] = msg.position[i];
    state.qd[index[i]] = msg.velocity[i];
  }
  out = std::move(state);
  return {};
}

Check command_from_message(const joint_command_t& msg, const dynamics::Model& model,
                           const RobotIdentity& identity, CommandSetpoint& out) {
  if (Check c = robot_field(msg.robot, identity, "joint_command_t"); !c.ok) return c;
  if (Check c = joint_count(msg.num_joints, model, "joint_command_t"); !c.ok) return c;
  if (!all_finite(msg.position.begin(), msg.position.end()) ||
      !all_finite(msg.velocity.begin(), msg.velocity.end()) ||
      !all_finite(msg.torque.begin(), msg.torque.end())) {
    return Check::fail("joint_command_t.position, velocity or torque is not finite");
  }
  std::vector<int> index;
  if (Check c = joint_indices(msg.joint_name, model, "joint_command_t", index); !c.ok) return c;
  CommandSetpoint setpoint;
  setpoint.utime = msg.utime;
  setpoint.plan_id = msg.plan_id;
  setpoint.q.setZero(model.nq());
  setpoint.qd.setZero(model.nq());
  setpoint.tau.setZero(model.nq());
  for (size_t i = 0; i < index.size(); ++i) {
    setpoint.q[index[i]] = msg.position[i];
    setpoint.qd[index[i]] = msg.velocity[i];
    setpoint.tau[index[i]] = msg.torque[i];
  }
  out = std::move(setpoint);
  return {};
}

joint_command_t command_to_message(const CommandSetpoint& setpoint, const dynamics::Model& model) {
  joint_command_t msg;
  msg.utime = setpoint.utime;
  msg.robot = model.name;
  msg.plan_id = setpoint.plan_id;
  msg.num_joints = model.nq();
  for (const auto& body : model.bodies) msg.joint_name.push_back(body.joint_name);
  msg.position.assign(setpoint.q.data(), setpoint.q.data() + setpoint.q.size());
  msg.velocity.assign(setpoint.qd.data(), setpoint.qd.data() + setpoint.qd.size());
  msg.torque.assign(setpoint.tau.data(), setpoint.tau.data() + setpoint.tau.size());
  return msg;
}

namespace {

void set_time(plan_t& msg, const PlanTime& time, bool has_trajectory) {
  msg.utime = time.utime;
  msg.clock = time.clock;
  msg.start_utime = has_trajectory ? time.start_utime : -1;
  msg.state_utime = time.state_utime;
  msg.takeover_utime = has_trajectory ? time.takeover_utime : -1;
}

}  // namespace

plan_t plan_to_message(const planning::Plan& plan, const dynamics::Model& model,
                       const std::string& robot, int64_t plan_id, int64_t goal_id,
                       const PlanTime& time) {
  plan_t msg;
  set_time(msg, time, plan.q.rows() > 0);
  msg.plan_id = plan_id;
  msg.goal_id = goal_id;
  msg.robot = robot;
  if (plan.success()) {
    msg.status = plan_t::SUCCESS;
  } else if (plan.stats.status == planning::PlanStatus::kInvalidProblem) {
    msg.status = plan_t::INVALID_GOAL;
  } else if (plan.q.rows() == 0) {
    msg.status = plan_t::FAILED;
  } else {
    msg.status = plan_t::NOT_CONVERGED;
  }
  if (!plan.success()) {
    std::string why = plan.stats.reason;
    for (const auto& f : plan.validation.failures) why += (why.empty() ? "" : "; ") + f;
    msg.status_message = why.empty() ? planning::to_string(plan.stats.status) : why;
  }
  msg.method = plan.stats.method;
  msg.num_joints = model.nq();
  for (const auto& body : model.bodies) msg.joint_name.push_back(body.joint_name);
  const int steps = static_cast<int>(plan.q.rows());
  msg.num_steps = steps;
  msg.t.assign(plan.t.begin(), plan.t.end());
  msg.t.resize(steps, 0.0);
  auto rows = [&](const Eigen::MatrixXd& m) {
    std::vector<std::vector<double>> out(steps, std::vector<double>(model.nq(), 0.0));
    for (int k = 0; k < steps && k < m.rows(); ++k) {
      for (int j = 0; j < model.nq() && j < m.cols(); ++j) out[k][j] = m(k, j);
    }
    return out;
  };
  msg.q = rows(plan.q);
  msg.qd = rows(plan.qd);
  msg.qdd = rows(plan.qdd);
  msg.tau = rows(plan.tau);
  msg.solve_time_s = plan.stats.solve_time_s;
  msg.iterations = plan.stats.iterations;
  msg.cost = plan.stats.cost;
  const auto& v = plan.validation;
  msg.max_dynamics_residual = v.max_dynamics_residual;
  msg.max_collocation_residual = std::max(v.max_position_consistency, v.max_velocity_consistency);
  // LCM doubles carry infinity fine, but receivers plotting it choke; no obstacle = large.
  msg.min_clearance = std::isfinite(v.min_clearance) ? v.min_clearance : 1e9;
  msg.goal_error = v.goal_error;
  msg.valid = v.valid;
  return msg;
}

plan_t failure_message(int8_t status, const std::string& reason, const std::string& robot,
                       int64_t plan_id, int64_t goal_id, const PlanTime& time) {
  plan_t msg;
  set_time(msg, time, /*has_trajectory=*/false);
  msg.plan_id = plan_id;
  msg.goal_id = goal_id;
  msg.robot = robot;
  msg.status = status;
  msg.status_message = reason;
  msg.method = "none";
  msg.num_joints = 0;
  msg.num_steps = 0;
  msg.solve_time_s = 0;
  msg.iterations = 0;
  msg.cost = 0;
  msg.max_dynamics_residual = 0;
  msg.max_collocation_residual = 0;
  msg.min_clearance = 0;
  msg.goal_error = 0;
  msg.valid = false;
  return msg;
}

namespace {

// Both versions of plan_t carry the trajectory and the figures in the same fields.
template <typename PlanMessage>
planning::Plan plan_from(const PlanMessage& msg) {
  planning::Plan plan;
  const int steps = msg.num_steps, n = msg.num_joints;
  plan.t.assign(msg.t.begin(), msg.t.end());
  auto matrix = [&](const std::vector<std::vector<double>>& rows) {
    Eigen::MatrixXd m(steps, n);
    for (int k = 0; k < steps; ++k) {
      for (int j = 0; j < n; ++j) m(k, j) = rows[k][j];
    }
    return m;
  };
  plan.q = matrix(msg.q);
  plan.qd = matrix(msg.qd);
  plan.qdd = matrix(msg.qdd);
  plan.tau = matrix(msg.tau);
  plan.stats.method = msg.method;
  plan.stats.status = msg.status == PlanMessage::SUCCESS ? planning::PlanStatus::kConverged
                      : msg.status == PlanMessage::INVALID_GOAL
                          ? planning::PlanStatus::kInvalidProblem
                      : msg.status == PlanMessage::NOT_CONVERGED ? planning::PlanStatus::kInfeasible
                                                                 : planning::PlanStatus::kFailed;
  if (msg.status != PlanMessage::SUCCESS) plan.stats.reason = msg.status_message;
  plan.stats.solve_time_s = msg.solve_time_s;
  plan.stats.iterations = msg.iterations;
  plan.stats.cost = msg.cost;
  plan.validation.valid = msg.valid;
  plan.validation.max_dynamics_residual = msg.max_dynamics_residual;
  plan.validation.min_clearance = msg.min_clearance;
  plan.validation.goal_error = msg.goal_error;
  return plan;
}

}  // namespace

planning::Plan plan_from_message(const plan_t& msg) { return plan_from(msg); }
planning::Plan plan_from_message(const plan_v1_t& msg) { return plan_from(msg); }

}  // namespace kinograph::messages

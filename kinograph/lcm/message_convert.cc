#include "kinograph/lcm/message_convert.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <unordered_map>

#include "kinograph/collision/convex_shape.h"
#include "kinograph/planning/io/data_dir.h"

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

namespace {

// Model index of each joint, by name.
std::unordered_map<std::string, int> joint_index_map(const dynamics::Model& model) {
  std::unordered_map<std::string, int> index;
  for (int j = 0; j < model.nq(); ++j) index[model.bodies[j].joint_name] = j;
  return index;
}

bool is_frame(const dynamics::Model& model, const std::string& name) {
  return std::any_of(model.frames.begin(), model.frames.end(),
                     [&](const auto& f) { return f.name == name; });
}

// The fields both goal versions share: robot, id, duration.
template <class GoalMessage>
Check goal_header(const std::string& type, const GoalMessage& msg, const RobotIdentity& identity,
                  GoalRequest& request) {
  if (Check c = robot_field(msg.robot, identity, type); !c.ok) return c;
  if (msg.goal_id < 0) return Check::fail(type + ".goal_id must be >= 0");
  if (!std::isfinite(msg.duration_s) || msg.duration_s < 0 || msg.duration_s > 3600) {
    return Check::fail(type + ".duration_s must be in [0, 3600] s (0 = default horizon)");
  }
  request.goal_id = msg.goal_id;
  request.utime = msg.utime;
  request.duration_s = msg.duration_s;
  return {};
}

// A pose goal of either version: a known frame, a finite position, a unit quaternion.
Check pose_goal(const std::string& type, const dynamics::Model& model, const std::string& frame,
                const double* position, const double* quaternion, planning::Goal& goal) {
  if (!is_frame(model, frame)) {
    return Check::fail(type + ".ee_frame \"" + frame + "\" is not a frame of " + model.name);
  }
  if (!all_finite(position, position + 3)) return Check::fail(type + ".ee_position is not finite");
  Eigen::Quaterniond rotation;
  if (Check c = quaternion_from(quaternion, type + ".ee_quaternion", rotation); !c.ok) return c;
  goal.kind = planning::Goal::Kind::kPose;
  goal.frame = frame;
  goal.pose = Eigen::Translation3d(position[0], position[1], position[2]) * rotation;
  return {};
}

Check task_constraint_from(const task_constraint_t& msg, const std::string& field,
                           const dynamics::Model& model, planning::TaskConstraint& out) {
  if (!is_frame(model, msg.frame)) {
    return Check::fail(field + ".frame \"" + msg.frame + "\" is not a frame of " + model.name);
  }
  if (!all_finite(msg.position, msg.position + 3)) {
    return Check::fail(field + ".position is not finite");
  }
  if (!std::isfinite(msg.tolerance) || msg.tolerance <= 0) {
    return Check::fail(field + ".tolerance must be > 0 (rad, and m)");
  }
  Eigen::Quaterniond rotation;
  if (Check c = quaternion_from(msg.quaternion, field + ".quaternion", rotation); !c.ok) return c;
  out.frame = msg.frame;
  out.orientation_only = msg.orientation_only;
  out.target = Eigen::Translation3d(msg.position[0], msg.position[1], msg.position[2]) * rotation;
  out.tolerance = msg.tolerance;
  return {};
}

}  // namespace

Check goal_from_message(const goal_t& msg, const dynamics::Model& model,
                        const RobotIdentity& identity, GoalRequest& out) {
  GoalRequest request;
  if (Check c = goal_header("goal_t", msg, identity, request); !c.ok) return c;
  if (msg.kind == goal_t::KIND_JOINT_CONFIGURATION) {
    if (msg.num_joints != model.nq()) {
      return Check::fail("goal_t.num_joints is " + std::to_string(msg.num_joints) + ", robot " +
                         model.name + " has " + std::to_string(model.nq()) +
                         " joints (goal_v2_t names its joints)");
    }
    if (!all_finite(msg.joint_position.begin(), msg.joint_position.end())) {
      return Check::fail("goal_t.joint_position is not finite");
    }
    request.goal.kind = planning::Goal::Kind::kJoint;
    request.goal.q = Eigen::Map<const Eigen::VectorXd>(msg.joint_position.data(), model.nq());
  } else if (msg.kind == goal_t::KIND_END_EFFECTOR_POSE) {
    if (Check c = pose_goal("goal_t", model, msg.ee_frame, msg.ee_position, msg.ee_quaternion,
                            request.goal);
        !c.ok) {
      return c;
    }
  } else {
    return Check::fail("goal_t.kind " + std::to_string(msg.kind) + " is unknown");
  }
  out = std::move(request);
  return {};
}

namespace {

// A goal of version 2 or later (joints by name, position only, task constraints): `type` names
// the message in the reasons.
template <class GoalMessage>
Check named_goal(const std::string& type, const GoalMessage& msg, const dynamics::Model& model,
                 const RobotIdentity& identity, GoalRequest& out) {
  GoalRequest request;
  if (Check c = goal_header(type, msg, identity, request); !c.ok) return c;
  if (msg.kind == goal_v2_t::KIND_JOINT_CONFIGURATION) {
    if (msg.joint_name.empty()) return Check::fail(type + ".joint_name names no joint");
    const std::unordered_map<std::string, int> index = joint_index_map(model);
    request.goal.kind = planning::Goal::Kind::kJoint;
    request.goal.q.setZero(model.nq());
    request.joint_named.assign(model.nq(), false);
    for (std::size_t i = 0; i < msg.joint_name.size(); ++i) {
      const std::string field = type + ".joint_name[" + std::to_string(i) + "] \"" +
                                msg.joint_name[i] + "\"";
      const auto it = index.find(msg.joint_name[i]);
      if (it == index.end()) return Check::fail(field + " is not a joint of " + model.name);
      if (request.joint_named[it->second]) return Check::fail(field + " appears twice");
      if (!std::isfinite(msg.joint_position[i])) {
        return Check::fail(type + ".joint_position of \"" + msg.joint_name[i] +
                           "\" is not finite");
      }
      request.joint_named[it->second] = true;
      request.goal.q[it->second] = msg.joint_position[i];
    }
  } else if (msg.kind == goal_v2_t::KIND_END_EFFECTOR_POSE) {
    if (Check c = pose_goal(type, model, msg.ee_frame, msg.ee_position,
                            msg.ee_quaternion, request.goal);
        !c.ok) {
      return c;
    }
    request.goal.position_only = msg.position_only;
  } else {
    return Check::fail(type + ".kind " + std::to_string(msg.kind) + " is unknown");
  }
  if (msg.task_constraint.size() > static_cast<std::size_t>(kMaxTaskConstraintsPerGoal)) {
    return Check::fail(type + ".num_task_constraints is " +
                       std::to_string(msg.task_constraint.size()) + ", more than the " +
                       std::to_string(kMaxTaskConstraintsPerGoal) + " one goal may carry");
  }
  for (std::size_t i = 0; i < msg.task_constraint.size(); ++i) {
    planning::TaskConstraint task;
    const std::string field = type + ".task_constraint[" + std::to_string(i) + "]";
    if (Check c = task_constraint_from(msg.task_constraint[i], field, model, task); !c.ok) {
      return c;
    }
    request.task_constraints.push_back(std::move(task));
  }
  out = std::move(request);
  return {};
}

// A goal tolerance from the wire: finite and >= 0 (0 = the validator's default).
Check tolerance_from(double value, const std::string& field, double& out) {
  if (!std::isfinite(value) || value < 0) {
    return Check::fail(field + " must be >= 0 (0 = the default)");
  }
  out = value;
  return {};
}

}  // namespace

Check goal_from_message(const goal_v2_t& msg, const dynamics::Model& model,
                        const RobotIdentity& identity, GoalRequest& out) {
  return named_goal("goal_v2_t", msg, model, identity, out);
}

Check goal_from_message(const goal_v3_t& msg, const dynamics::Model& model,
                        const RobotIdentity& identity, GoalRequest& out) {
  GoalRequest request;
  if (Check c = named_goal("goal_v3_t", msg, model, identity, request); !c.ok) return c;
  planning::Goal& goal = request.goal;
  if (goal.kind == planning::Goal::Kind::kJoint) {
    // named_goal has checked every name is a joint, once.
    const std::unordered_map<std::string, int> index = joint_index_map(model);
    goal.joint_tolerance.setZero(model.nq());
    for (std::size_t i = 0; i < msg.joint_name.size(); ++i) {
      const int j = index.at(msg.joint_name[i]);
      const std::string field = "goal_v3_t.joint_tolerance of \"" + msg.joint_name[i] + "\"";
      if (Check c = tolerance_from(msg.joint_tolerance[i], field, goal.joint_tolerance[j]); !c.ok)
        return c;
    }
  } else if (!msg.joint_tolerance.empty()) {
    return Check::fail("goal_v3_t.joint_tolerance is for joint goals; a pose goal has none");
  }
  if (Check c = tolerance_from(msg.position_tolerance_m, "goal_v3_t.position_tolerance_m",
                               goal.position_tolerance);
      !c.ok) {
    return c;
  }
  if (Check c = tolerance_from(msg.orientation_tolerance_rad,
                               "goal_v3_t.orientation_tolerance_rad", goal.orientation_tolerance);
      !c.ok) {
    return c;
  }
  out = std::move(request);
  return {};
}

planning::Goal goal_for_start(const GoalRequest& request, const Eigen::VectorXd& start_q) {
  planning::Goal goal = request.goal;
  if (goal.kind != planning::Goal::Kind::kJoint || request.joint_named.empty()) return goal;
  for (std::size_t j = 0; j < request.joint_named.size(); ++j) {
    if (!request.joint_named[j] && static_cast<Eigen::Index>(j) < start_q.size())
      goal.q[j] = start_q[j];
  }
  return goal;
}

obstacle_list_t obstacle_list_from_v1(const obstacle_list_v1_t& msg) {
  obstacle_list_t out;
  out.utime = msg.utime;
  out.num_obstacles = msg.num_obstacles;
  out.obstacles = msg.obstacles;
  out.replace_all = msg.replace_all;
  return out;
}

namespace {

// An obstacle's pose from the wire: a position within the collision engine's range and a unit
// quaternion; `field` is the entry's key, `named` the same with its id.
Check obstacle_pose(const std::string& field, const std::string& named, const double* position,
                    const double* quaternion, Eigen::Isometry3d& pose) {
  const Eigen::Vector3d p(position[0], position[1], position[2]);
  if (std::string e = collision::position_range_error(p); !e.empty()) {
    return Check::fail(named + ": " + e);
  }
  Eigen::Quaterniond rotation;
  if (Check c = quaternion_from(quaternion, field + ".quaternion", rotation); !c.ok) return c;
  pose = Eigen::Translation3d(p) * rotation;
  return {};
}

}  // namespace

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
    u.source = msg.source;
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
    if (Check ch = obstacle_pose(field, named, o.position, o.quaternion, u.pose); !ch.ok) return ch;
    updates.push_back(std::move(u));
  }
  out = std::move(updates);
  return {};
}

Check mesh_obstacles_from_message(const mesh_obstacle_list_t& msg, const std::string& anchor_dir,
                                  std::vector<ObstacleUpdate>& out) {
  if (msg.obstacles.size() > static_cast<size_t>(kMaxMeshObstaclesPerMessage)) {
    return Check::fail("mesh_obstacle_list_t.num_obstacles is " +
                       std::to_string(msg.obstacles.size()) + ", more than the " +
                       std::to_string(kMaxMeshObstaclesPerMessage) + " one message may carry");
  }
  std::vector<ObstacleUpdate> updates;
  for (size_t i = 0; i < msg.obstacles.size(); ++i) {
    const mesh_obstacle_t& o = msg.obstacles[i];
    const std::string field = "mesh_obstacle_list_t.obstacles[" + std::to_string(i) + "]";
    if (o.id.empty()) return Check::fail(field + ".id is empty");
    ObstacleUpdate u;
    u.source = msg.source;
    u.id = o.id;
    if (o.action == mesh_obstacle_t::REMOVE) {
      u.remove = true;
      updates.push_back(std::move(u));
      continue;
    }
    if (o.action != mesh_obstacle_t::ADD_OR_MOVE) {
      return Check::fail(field + ".action " + std::to_string(o.action) + " is unknown");
    }
    const std::string named = field + " (\"" + o.id + "\")";
    if (!all_finite(o.scale, o.scale + 3) || !all_finite(o.position, o.position + 3)) {
      return Check::fail(named + " has a non-finite scale or position");
    }
    const Eigen::Vector3d scale(o.scale[0], o.scale[1], o.scale[2]);
    if (scale.minCoeff() <= 0) return Check::fail(named + ".scale must be > 0");
    const std::optional<std::string> path = planning::resolve_scene_path(o.mesh, anchor_dir);
    if (!path) {
      return Check::fail(named + ".mesh: file '" + o.mesh + "' not found (looked next to the " +
                         "daemon's scene and in " + planning::describe_data_dirs() + ")");
    }
    u.shape = collision::Shape::mesh(*path, scale);
    if (std::string e = collision::range_error(u.shape); !e.empty()) {
      return Check::fail(named + ".scale: " + e);
    }
    if (Check c = obstacle_pose(field, named, o.position, o.quaternion, u.pose); !c.ok) return c;
    // Read here, once: a file that is no mesh is refused now, not when a plan needs it.
    try {
      collision::ConvexShape hull(u.shape);
    } catch (const std::exception& e) {
      return Check::fail(named + ".mesh: " + e.what());
    }
    updates.push_back(std::move(u));
  }
  out = std::move(updates);
  return {};
}

Check payload_from_message(const payload_t& msg, const dynamics::Model& model,
                           const RobotIdentity& identity, PayloadChange& out) {
  if (Check c = robot_field(msg.robot, identity, "payload_t"); !c.ok) return c;
  PayloadChange change;
  change.utime = msg.utime;
  if (msg.action == payload_t::DETACH) {
    out = std::move(change);
    return {};
  }
  if (msg.action != payload_t::ATTACH) {
    return Check::fail("payload_t.action " + std::to_string(msg.action) + " is unknown");
  }
  if (!is_frame(model, msg.frame)) {
    return Check::fail("payload_t.frame \"" + msg.frame + "\" is not a frame of " + model.name);
  }
  if (!std::isfinite(msg.mass_kg) || msg.mass_kg < 0 || msg.mass_kg > kMaxPayloadMassKg) {
    return Check::fail("payload_t.mass_kg must be in [0, " + std::to_string(kMaxPayloadMassKg) +
                       "] kg");
  }
  if (!all_finite(msg.size, msg.size + 3) || !all_finite(msg.offset, msg.offset + 3)) {
    return Check::fail("payload_t has a non-finite size or offset");
  }
  planning::PayloadSpec spec;
  spec.frame = msg.frame;
  spec.mass = msg.mass_kg;
  spec.size = Eigen::Vector3d(msg.size[0], msg.size[1], msg.size[2]);
  spec.offset = Eigen::Vector3d(msg.offset[0], msg.offset[1], msg.offset[2]);
  if (spec.size.minCoeff() <= 0) return Check::fail("payload_t.size must be > 0");
  const collision::Shape box = collision::Shape::box(spec.size.x(), spec.size.y(), spec.size.z());
  if (std::string e = collision::range_error(box); !e.empty()) {
    return Check::fail("payload_t.size: " + e);
  }
  if (std::string e = collision::position_range_error(spec.offset); !e.empty()) {
    return Check::fail("payload_t.offset: " + e);
  }
  change.payload = std::move(spec);
  out = std::move(change);
  return {};
}

namespace {

// Model index of each entry of a message's joint_name list, which may be in any order but must
// name every joint of the model once.
Check joint_indices(const std::vector<std::string>& names, const dynamics::Model& model,
                    const std::string& type, std::vector<int>& out) {
  const int n = model.nq();
  const std::unordered_map<std::string, int> index = joint_index_map(model);
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
  if (!all_finite(msg.position.begin(), msg.position.end()) ||
      !all_finite(msg.velocity.begin(), msg.velocity.end())) {
    return Check::fail("robot_state_t.position or velocity is not finite");
  }
  const int n = model.nq();
  const std::unordered_map<std::string, int> index = joint_index_map(model);
  MeasuredState state;
  state.utime = msg.utime;
  state.q.setZero(n);
  state.qd.setZero(n);
  std::vector<bool> seen(n, false);
  std::vector<std::string> ignored;  // joints of the robot the model does not have
  for (std::size_t i = 0; i < msg.joint_name.size(); ++i) {
    const auto it = index.find(msg.joint_name[i]);
    if (it == index.end()) {
      ignored.push_back(msg.joint_name[i]);
      continue;
    }
    if (seen[it->second]) {
      return Check::fail("robot_state_t.joint_name \"" + msg.joint_name[i] + "\" appears twice");
    }
    seen[it->second] = true;
    state.q[it->second] = msg.position[i];
    state.qd[it->second] = msg.velocity[i];
  }
  for (int j = 0; j < n; ++j) {
    if (seen[j]) continue;
    std::string why = "robot_state_t names no joint \"" + model.bodies[j].joint_name +
                      "\" of " + model.name;
    // A misspelt name is among those ignored: say which they were.
    if (!ignored.empty()) {
      why += " (it names " + std::to_string(ignored.size()) + " joint" +
             (ignored.size() == 1 ? "" : "s") + " the robot does not have, e.g. \"" +
             ignored.front() + "\")";
    }
    return Check::fail(why);
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

#pragma once
// Sample kinograph LCM messages with seeded random contents, shared by the lcmtypes tests.
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "drake/lcmt_iiwa_status.hpp"
#include "drake/lcmt_robot_plan.hpp"
#include "kinograph/goal_t.hpp"
#include "kinograph/goal_v2_t.hpp"
#include "kinograph/goal_v3_t.hpp"
#include "kinograph/joint_command_t.hpp"
#include "kinograph/mesh_obstacle_list_t.hpp"
#include "kinograph/obstacle_list_t.hpp"
#include "kinograph/obstacle_list_v1_t.hpp"
#include "kinograph/obstacle_t.hpp"
#include "kinograph/payload_t.hpp"
#include "kinograph/plan_t.hpp"
#include "kinograph/plan_v1_t.hpp"
#include "kinograph/planner_status_t.hpp"
#include "kinograph/robot_state_t.hpp"
#include "kinograph/stop_request_t.hpp"

namespace kinograph::lcmtypes::testing {

using kinograph::goal_t;
using kinograph::goal_v2_t;
using kinograph::goal_v3_t;
using kinograph::mesh_obstacle_list_t;
using kinograph::mesh_obstacle_t;
using kinograph::payload_t;
using kinograph::task_constraint_t;
using kinograph::joint_command_t;
using kinograph::obstacle_list_t;
using kinograph::obstacle_t;
using kinograph::plan_t;
using kinograph::plan_v1_t;
using kinograph::planner_status_t;
using kinograph::robot_state_t;
using kinograph::stop_request_t;

inline std::mt19937& rng() {
  static std::mt19937 engine(20240611);
  return engine;
}

inline double random_double() { return std::uniform_real_distribution<double>(-10.0, 10.0)(rng()); }

inline std::vector<double> random_vector(int n) {
  std::vector<double> v(n);
  for (double& x : v) x = random_double();
  return v;
}

inline std::vector<std::string> joint_names(int n) {
  std::vector<std::string> names;
  for (int i = 1; i <= n; ++i) names.push_back("iiwa_joint_" + std::to_string(i));
  return names;
}

inline robot_state_t make_robot_state() {
  robot_state_t m;
  m.utime = 1'700'000'000'123'456;
  m.robot = "iiwa14";
  m.num_joints = 7;
  m.joint_name = joint_names(7);
  m.position = random_vector(7);
  m.velocity = random_vector(7);
  return m;
}

inline goal_t make_goal() {
  goal_t m;
  m.utime = 42;
  m.goal_id = 9'000'000'001;
  m.robot = "iiwa14";
  m.kind = goal_t::KIND_END_EFFECTOR_POSE;
  m.num_joints = 0;
  m.ee_frame = "iiwa_link_ee_kuka";
  for (double& x : m.ee_position) x = random_double();
  const double q[4] = {0.5, 0.5, -0.5, 0.5};
  for (int i = 0; i < 4; ++i) m.ee_quaternion[i] = q[i];
  m.duration_s = 2.5;
  return m;
}

/// A goal_v2_t joint goal moving the joints `names` to `q`, with no task constraint.
inline goal_v2_t joint_goal_by_name(int64_t id, std::vector<std::string> names,
                                    std::vector<double> q) {
  goal_v2_t g{};
  g.goal_id = id;
  g.kind = goal_v2_t::KIND_JOINT_CONFIGURATION;
  g.num_joints = static_cast<int32_t>(names.size());
  g.joint_name = std::move(names);
  g.joint_position = std::move(q);
  g.ee_quaternion[0] = 1;
  return g;
}

// A joint goal by name with two task constraints (all of goal_v2_t's arrays filled).
inline goal_v2_t make_goal_v2() {
  goal_v2_t m = joint_goal_by_name(9'000'000'002, {"iiwa_joint_2", "iiwa_joint_7"},
                                   {random_double(), random_double()});
  m.utime = 43;
  m.robot = "iiwa14";
  const double q[4] = {1, 0, 0, 0};
  m.position_only = true;
  m.duration_s = 1.5;
  for (const char* frame : {"iiwa_link_ee_kuka", "iiwa_link_7"}) {
    task_constraint_t t;
    t.frame = frame;
    t.orientation_only = frame[5] == 'l';
    for (double& x : t.position) x = random_double();
    for (int i = 0; i < 4; ++i) t.quaternion[i] = q[i];
    t.tolerance = 0.05;
    m.task_constraint.push_back(t);
  }
  m.num_task_constraints = 2;
  return m;
}

// goal_v2_t's sample as a goal_v3_t, with a tolerance per joint and for a pose.
inline goal_v3_t make_goal_v3() {
  const goal_v2_t v2 = make_goal_v2();
  goal_v3_t m;
  m.utime = v2.utime;
  m.goal_id = v2.goal_id;
  m.robot = v2.robot;
  m.kind = v2.kind;
  m.num_joints = v2.num_joints;
  m.joint_name = v2.joint_name;
  m.joint_position = v2.joint_position;
  m.ee_frame = v2.ee_frame;
  std::copy(std::begin(v2.ee_position), std::end(v2.ee_position), m.ee_position);
  std::copy(std::begin(v2.ee_quaternion), std::end(v2.ee_quaternion), m.ee_quaternion);
  m.position_only = v2.position_only;
  m.duration_s = v2.duration_s;
  m.num_task_constraints = v2.num_task_constraints;
  m.task_constraint = v2.task_constraint;
  m.joint_tolerance.assign(v2.joint_name.size(), 1e-3);
  m.position_tolerance_m = 0.02;
  m.orientation_tolerance_rad = 0.03;
  return m;
}

inline payload_t make_payload() {
  payload_t m;
  m.utime = 44;
  m.robot = "iiwa14";
  m.action = payload_t::ATTACH;
  m.frame = "iiwa_link_ee_kuka";
  m.mass_kg = 2.0;
  for (int i = 0; i < 3; ++i) {
    m.size[i] = 0.1 * (i + 1);
    m.offset[i] = 0.01 * i;
  }
  return m;
}

inline mesh_obstacle_list_t make_mesh_obstacle_list() {
  mesh_obstacle_list_t m;
  m.utime = 45;
  m.source = "perception";
  for (const char* id : {"part", "fixture"}) {
    mesh_obstacle_t o;
    o.id = id;
    o.action = mesh_obstacle_t::ADD_OR_MOVE;
    o.mesh = std::string("meshes/") + id + ".obj";
    for (int i = 0; i < 3; ++i) {
      o.scale[i] = 1.0;
      o.position[i] = random_double();
    }
    const double q[4] = {1, 0, 0, 0};
    std::copy(q, q + 4, o.quaternion);
    m.obstacles.push_back(o);
  }
  m.num_obstacles = 2;
  return m;
}

inline obstacle_t make_obstacle(const std::string& id, int8_t shape) {
  obstacle_t m;
  m.id = id;
  m.action = obstacle_t::ADD_OR_MOVE;
  m.shape = shape;
  for (double& x : m.size) x = std::abs(random_double());
  for (double& x : m.position) x = random_double();
  const double q[4] = {1, 0, 0, 0};
  for (int i = 0; i < 4; ++i) m.quaternion[i] = q[i];
  return m;
}

inline obstacle_list_t make_obstacle_list() {
  obstacle_list_t m;
  m.utime = 7;
  m.source = "perception";
  m.obstacles = {make_obstacle("table", obstacle_t::BOX), make_obstacle("ball", obstacle_t::SPHERE),
                 make_obstacle("pole", obstacle_t::CYLINDER),
                 make_obstacle("arm", obstacle_t::CAPSULE)};
  m.obstacles[1].action = obstacle_t::REMOVE;
  m.num_obstacles = static_cast<int32_t>(m.obstacles.size());
  m.replace_all = true;
  return m;
}

// The same updates as version 1 (no source).
inline kinograph::obstacle_list_v1_t make_obstacle_list_v1() {
  const obstacle_list_t v2 = make_obstacle_list();
  kinograph::obstacle_list_v1_t m;
  m.utime = v2.utime;
  m.num_obstacles = v2.num_obstacles;
  m.obstacles = v2.obstacles;
  m.replace_all = v2.replace_all;
  return m;
}

// Either version of plan_t (version 2 adds the clock fields, filled by make_plan).
template <typename PlanMessage>
inline PlanMessage make_plan_of_version(int num_steps) {
  const int n = 7;
  PlanMessage m;
  m.utime = 123;
  m.plan_id = 5;
  m.goal_id = 9'000'000'001;
  m.robot = "iiwa14";
  m.status = PlanMessage::SUCCESS;
  m.status_message = "";
  m.method = "incremental";
  m.num_joints = n;
  m.joint_name = joint_names(n);
  m.num_steps = num_steps;
  for (int k = 0; k < num_steps; ++k) {
    m.t.push_back(0.1 * k);
    m.q.push_back(random_vector(n));
    m.qd.push_back(random_vector(n));
    m.qdd.push_back(random_vector(n));
    m.tau.push_back(random_vector(n));
  }
  m.solve_time_s = 0.0123;
  m.iterations = 17;
  m.cost = 3.25;
  m.max_dynamics_residual = 1e-9;
  m.max_collocation_residual = 2e-9;
  m.min_clearance = 0.031;
  m.goal_error = 1e-4;
  m.valid = true;
  return m;
}

inline plan_t make_plan(int num_steps) {
  plan_t m = make_plan_of_version<plan_t>(num_steps);
  m.clock = plan_t::CLOCK_ROBOT;
  m.start_utime = 5'000'000;
  m.state_utime = 5'000'000;
  m.takeover_utime = 5'000'000;
  return m;
}

inline plan_v1_t make_plan_v1(int num_steps) { return make_plan_of_version<plan_v1_t>(num_steps); }

inline joint_command_t make_joint_command() {
  joint_command_t m;
  m.utime = 5'005'000;
  m.robot = "iiwa14";
  m.plan_id = 12;
  m.num_joints = 7;
  m.joint_name = joint_names(7);
  m.position = random_vector(7);
  m.velocity = random_vector(7);
  m.torque = random_vector(7);
  return m;
}

inline stop_request_t make_stop_request() {
  stop_request_t m;
  m.utime = 5'010'000;
  m.robot = "iiwa14";
  m.request_id = 3;
  m.reason = "operator";
  return m;
}

inline drake::lcmt_iiwa_status make_iiwa_status() {
  drake::lcmt_iiwa_status m;
  m.utime = 5'000'000;
  m.num_joints = 7;
  for (auto* v : {&m.joint_position_measured, &m.joint_velocity_estimated,
                  &m.joint_position_commanded, &m.joint_position_ipo, &m.joint_torque_measured,
                  &m.joint_torque_commanded, &m.joint_torque_external}) {
    *v = random_vector(7);
  }
  return m;
}

inline drake::lcmt_robot_plan make_robot_plan(int num_states) {
  drake::lcmt_robot_plan m;
  m.utime = 5'000'000;
  m.num_states = num_states;
  for (int k = 0; k < num_states; ++k) {
    drake::lcmt_robot_state s;
    s.utime = 100'000 * k;
    s.num_joints = 7;
    s.joint_name = joint_names(7);
    for (double x : random_vector(7)) s.joint_position.push_back(static_cast<float>(x));
    m.plan.push_back(std::move(s));
  }
  return m;
}

inline planner_status_t make_planner_status() {
  planner_status_t m;
  m.utime = 99;
  m.robot = "acrobot";
  m.state = planner_status_t::ERROR;
  m.last_goal_id = 3;
  m.last_plan_id = -1;
  m.message = "goal 3 rejected: joint_position has 3 entries, robot has 2 joints";
  m.num_plans = 2;
  m.num_failures = 1;
  m.num_goals_received = 5;
  m.num_goals_answered = 4;
  m.num_goals_superseded = 1;
  m.num_goals_dropped = 2;
  m.model_id = "acrobot:0123456789abcdef";
  m.base_position[0] = 1.3;
  m.base_quaternion[0] = 1.0;
  m.goal_utime = 42;
  m.valid_plan_id = 1;
  m.num_neighbour_replans = 3;
  m.neighbours = "right: plan 3, followed";
  m.planning_goal_utime = 43;
  return m;
}

/// The message's bytes as LCM sends them (empty if encoding failed).
template <typename Msg>
std::vector<uint8_t> encode(const Msg& m) {
  const int size = m.getEncodedSize();
  std::vector<uint8_t> buf(size);
  if (m.encode(buf.data(), 0, size) != size) buf.clear();
  return buf;
}

}  // namespace kinograph::lcmtypes::testing

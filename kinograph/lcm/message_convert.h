#pragma once
// Conversions between the kinograph LCM messages and the planner's types, with the checks a
// message from the network needs (robot name, joint count and names, finite numbers, sizes,
// unit quaternions). A message that fails a check is rejected with a reason naming the field.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "kinograph/collision/shape.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/goal_t.hpp"
#include "kinograph/goal_v2_t.hpp"
#include "kinograph/goal_v3_t.hpp"
#include "kinograph/joint_command_t.hpp"
#include "kinograph/mesh_obstacle_list_t.hpp"
#include "kinograph/obstacle_list_t.hpp"
#include "kinograph/obstacle_list_v1_t.hpp"
#include "kinograph/payload_t.hpp"
#include "kinograph/plan_t.hpp"
#include "kinograph/plan_v1_t.hpp"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"
#include "kinograph/robot_state_t.hpp"

namespace kinograph::messages {

/// Outcome of checking one message: ok, or why it was rejected.
struct Check {
  bool ok = true;
  std::string reason;
  static Check fail(std::string why) { return {false, std::move(why)}; }
};

/// Who a daemon is: the names a message's `robot` field may carry (compared without case; an
/// empty field is accepted) and the joint order of its model.
struct RobotIdentity {
  std::string model_name;      ///< URDF robot name, e.g. "iiwa14"
  std::string channel_prefix;  ///< e.g. "IIWA"
  bool matches(const std::string& robot) const;
};

/// A goal as the planner takes it, with the id it must be answered under.
struct GoalRequest {
  int64_t goal_id = -1;
  int64_t utime = 0;
  planning::Goal goal;
  double duration_s = 0;  ///< 0 = the scene's horizon
  /// Joint goals: which joints (model order) the goal names; the others are held at the
  /// plan's start (goal_for_start). Empty = every joint named.
  std::vector<bool> joint_named;
  /// Task constraints the goal adds to the scene's (goal_v2_t).
  std::vector<planning::TaskConstraint> task_constraints;
};

/// One obstacle change from an obstacle_list_t.
struct ObstacleUpdate {
  std::string source;  ///< the list's source ("" from version-1 senders); ids are per source
  std::string id;
  bool remove = false;
  collision::Shape shape;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

/// A measured robot state in the model's joint order.
struct MeasuredState {
  int64_t utime = 0;
  Eigen::VectorXd q, qd;
};

/// A joint setpoint from a joint_command_t, in the model's joint order.
struct CommandSetpoint {
  int64_t utime = 0;
  int64_t plan_id = -1;
  Eigen::VectorXd q, qd, tau;
};

/// Checks a goal_t against the model and converts it. Limits and reachability are left to the
/// planner's own problem check, which answers with INVALID_GOAL.
Check goal_from_message(const goal_t& msg, const dynamics::Model& model,
                        const RobotIdentity& identity, GoalRequest& out);

/// Most task constraints one goal_v2_t may carry (each adds a factor per step).
inline constexpr int kMaxTaskConstraintsPerGoal = 16;

/// Checks a goal_v2_t against the model and converts it: joints by name (any order, a subset;
/// unknown or repeated names refused, naming them), position-only pose goals and task
/// constraints (frames known, unit quaternions, tolerance > 0).
Check goal_from_message(const goal_v2_t& msg, const dynamics::Model& model,
                        const RobotIdentity& identity, GoalRequest& out);

/// Checks a goal_v3_t as a goal_v2_t, then its tolerances (finite, >= 0; 0 = the validator's
/// default), which become the goal's: per named joint, or position and orientation.
Check goal_from_message(const goal_v3_t& msg, const dynamics::Model& model,
                        const RobotIdentity& identity, GoalRequest& out);

/// The goal to plan from `start_q`: a joint goal's joints the request does not name are held
/// at their start position.
planning::Goal goal_for_start(const GoalRequest& request, const Eigen::VectorXd& start_q);

/// Most obstacle changes one obstacle_list_t may carry.
inline constexpr int kMaxObstaclesPerMessage = 256;

/// An obstacle (or its removal) is named by its source and its id within the source.
using ObstacleKey = std::pair<std::string, std::string>;

/// A version-1 obstacle list as version 2: the same updates from the unnamed source "".
obstacle_list_t obstacle_list_from_v1(const obstacle_list_v1_t& msg);

/// Checks an obstacle_list_t and converts it, each update carrying the list's source; on failure
/// nothing is converted. Refuses more than kMaxObstaclesPerMessage entries (before converting any)
/// and any shape or position outside the collision engine's faithful range (collision/shape.h),
/// naming the obstacle.
Check obstacles_from_message(const obstacle_list_t& msg, std::vector<ObstacleUpdate>& out);

/// Most mesh obstacles one mesh_obstacle_list_t may carry (each is read from disk on arrival).
inline constexpr int kMaxMeshObstaclesPerMessage = 16;

/// Checks a mesh_obstacle_list_t and converts it, each update carrying the list's source. Mesh
/// paths resolve as a scene's do: absolute, else against `anchor_dir` (the daemon's scene
/// directory), else the data directories; each mesh is read here, so a file that is missing or
/// no mesh is refused naming it, as are a scale or position beyond the collision engine's range.
Check mesh_obstacles_from_message(const mesh_obstacle_list_t& msg, const std::string& anchor_dir,
                                  std::vector<ObstacleUpdate>& out);

/// Heaviest payload a payload_t may attach (kg).
inline constexpr double kMaxPayloadMassKg = 1e4;

/// A payload change from a payload_t: the box to carry (a scene's robot.payload), or none.
struct PayloadChange {
  int64_t utime = 0;
  std::optional<planning::PayloadSpec> payload;  ///< nullopt = detach
};

/// Checks a payload_t against the model (a known frame; mass, size and offset finite and in
/// range) and converts it. Whether the box can be attached there is the scene reader's check.
Check payload_from_message(const payload_t& msg, const dynamics::Model& model,
                           const RobotIdentity& identity, PayloadChange& out);

/// Checks a robot_state_t and converts it to model order. Its joints may come in any order,
/// and joints the model does not have (a gripper's) are ignored; a model joint it does not
/// name, or names twice, is refused naming it.
Check state_from_message(const robot_state_t& msg, const dynamics::Model& model,
                         const RobotIdentity& identity, MeasuredState& out);

/// Checks a joint_command_t (joint names may come in any order) and converts it to model order.
Check command_from_message(const joint_command_t& msg, const dynamics::Model& model,
                           const RobotIdentity& identity, CommandSetpoint& out);

/// The joint_command_t of a setpoint in the model's joint order.
joint_command_t command_to_message(const CommandSetpoint& setpoint, const dynamics::Model& model);

/// Where a plan sits in time (plan_t's clock fields, lcmtypes/README.md "Time"): the clock and,
/// on it, the publication time, knot 0's time, the measured state knot 0 is and the take-over.
struct PlanTime {
  int8_t clock = plan_t::CLOCK_WALL;
  int64_t utime = 0;            ///< publication (µs)
  int64_t start_utime = -1;     ///< knot 0 (µs); -1 without a trajectory
  int64_t state_utime = -1;     ///< the robot_state_t knot 0 starts from; -1 = the scene's start
  int64_t takeover_utime = -1;  ///< when the plan replaces the one before it (µs)
};

/// The plan_t answering goal `goal_id`: status SUCCESS only for a plan that validated. A plan
/// without trajectory gets start_utime = takeover_utime = -1 whatever `time` says.
plan_t plan_to_message(const planning::Plan& plan, const dynamics::Model& model,
                       const std::string& robot, int64_t plan_id, int64_t goal_id,
                       const PlanTime& time);

/// A plan_t with no trajectory that answers a goal with a failure status and reason.
plan_t failure_message(int8_t status, const std::string& reason, const std::string& robot,
                       int64_t plan_id, int64_t goal_id, const PlanTime& time);

/// The planner's view of a plan_t (trajectory only; validation figures as sent).
planning::Plan plan_from_message(const plan_t& msg);
/// The same for a plan of version 1 (old logs), which has no clock fields.
planning::Plan plan_from_message(const plan_v1_t& msg);

}  // namespace kinograph::messages

#pragma once
// Conversions between the kinograph LCM messages and the planner's types, with the checks a
// message from the network needs (robot name, joint count and names, finite numbers, sizes,
// unit quaternions). A message that fails a check is rejected with a reason naming the field.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "kinograph/collision/shape.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/goal_t.hpp"
#include "kinograph/joint_command_t.hpp"
#include "kinograph/obstacle_list_t.hpp"
#include "kinograph/plan_t.hpp"
#include "kinograph/plan_v1_t.hpp"
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
};

/// One obstacle change from an obstacle_list_t.
struct ObstacleUpdate {
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

/// Most obstacle changes one obstacle_list_t may carry.
inline constexpr int kMaxObstaclesPerMessage = 256;

/// Checks an obstacle_list_t and converts it; on failure nothing is converted. Refuses more
/// than kMaxObstaclesPerMessage entries (before converting any) and any shape or position
/// outside the collision engine's faithful range (collision/shape.h), naming the obstacle.
Check obstacles_from_message(const obstacle_list_t& msg, std::vector<ObstacleUpdate>& out);

/// Checks a robot_state_t (joint names may come in any order) and converts it to model order.
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

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
#include "kinograph/obstacle_list_t.hpp"
#include "kinograph/plan_t.hpp"
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

/// The plan_t answering goal `goal_id`: status SUCCESS only for a plan that validated.
plan_t plan_to_message(const planning::Plan& plan, const dynamics::Model& model,
                       const std::string& robot, int64_t plan_id, int64_t goal_id, int64_t utime);

/// A plan_t with no trajectory that answers a goal with a failure status and reason.
plan_t failure_message(int8_t status, const std::string& reason, const std::string& robot,
                       int64_t plan_id, int64_t goal_id, int64_t utime);

/// The planner's view of a plan_t (trajectory only; validation figures as sent).
planning::Plan plan_from_message(const plan_t& msg);

}  // namespace kinograph::messages

#pragma once
// Conversions between Drake's LCM messages (package drake: the iiwa driver's status, robot
// plans) and kinograph's, so that a Drake iiwa driver setup can use kinographd.
#include "drake/lcmt_iiwa_status.hpp"
#include "drake/lcmt_robot_plan.hpp"
#include "kinograph/dynamics/model.h"
#include "kinograph/lcm/message_convert.h"
#include "kinograph/plan_t.hpp"

namespace kinograph::messages {

/// Checks a Drake iiwa status and reads it as the measured state: joint_position_measured and
/// joint_velocity_estimated, in the model's joint order (the status names no joints).
Check state_from_iiwa_status(const drake::lcmt_iiwa_status& msg, const dynamics::Model& model,
                             MeasuredState& out);

/// A plan with a trajectory as Drake's robot plan: one knot per step with its time within the
/// plan (µs, t[k] − t[0]), the joint names and positions (as float, Drake's type); utime is
/// the plan's start_utime. Throws std::invalid_argument for a plan without trajectory.
drake::lcmt_robot_plan robot_plan_from_plan(const plan_t& plan);

}  // namespace kinograph::messages

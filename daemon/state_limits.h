#pragma once
// Whether a measured state can be a plan's start: a state beyond the robot's limits is a
// sensor fault or another robot, and planning from it would give a plan that starts invalid.
#include <string>

#include "kinograph/dynamics/model.h"
#include "kinograph/lcm/message_convert.h"
#include "kinograph/robot_state_t.hpp"

namespace kinograph::daemon {

/// How far a measured joint position may be beyond [lower, upper] (rad or m): encoders read a
/// little past a hard stop.
constexpr double kStatePositionTolerance = 0.01;
/// How much a measured joint speed may exceed the velocity limit, as a fraction of it
/// (velocities are estimated, hence noisy).
constexpr double kStateVelocityTolerance = 0.05;

/// Why `state` cannot be a start — the first joint, by name, beyond its position limits or
/// velocity limit by more than the tolerances, with the amount — or empty when it can.
std::string state_beyond_limits(const messages::MeasuredState& state, const dynamics::Model& model);

/// Which joint of a robot_state_t has a non-finite position or velocity (by name, with the
/// value), or empty; checked on the message, before it is converted.
std::string non_finite_joint(const robot_state_t& msg);

}  // namespace kinograph::daemon

#pragma once
// How planning messages name things for the user: joints by number and URDF name, values with
// their units, times in seconds.
#include <string>
#include <utility>

#include "kinograph/dynamics/model.h"

namespace kinograph::planning {

/// "joint 4 (iiwa_joint_4)": the 1-based number users count in, and the URDF joint name.
std::string joint_label(const dynamics::Model& model, int joint);

/// The unit of joint `joint`'s quantity: derivative 0 position (rad or m), 1 velocity, 2
/// acceleration, 3 effort (N·m or N).
std::string joint_unit(const dynamics::Model& model, int joint, int derivative);

/// A number as messages print it (`digits` significant digits, no trailing zeros).
std::string number(double x, int digits = 3);

/// `x` and `y` printed with the fewest significant digits (3 or more) that tell them apart, so
/// "needs 2.001 s; the horizon is 2 s" never reads "needs 2 s; the horizon is 2 s".
std::pair<std::string, std::string> distinct_numbers(double x, double y);

/// "t = 5.5 s".
std::string at_time(double t);

/// A q, q̇, q̈ (derivative 0..2) or τ (3) value z of `joint` at time t against the joint's own
/// limit; when z is inside that limit but past the planner's tightened bound [lower, upper] by
/// `violation`, says so.
std::string limit_text(const dynamics::Model& model, int derivative, int joint, double z,
                       double lower, double upper, double violation, double t);

/// A torque row of `joint`: on an unactuated joint (`unactuated`) the torque it would need,
/// otherwise limit_text for the effort.
std::string torque_text(const dynamics::Model& model, int joint, bool unactuated, double z,
                        double lower, double upper, double violation, double t);

}  // namespace kinograph::planning

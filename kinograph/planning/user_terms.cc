#include "kinograph/planning/user_terms.h"

#include <algorithm>
#include <iomanip>
#include <sstream>

namespace kinograph::planning {

std::string joint_label(const dynamics::Model& model, int joint) {
  return "joint " + std::to_string(joint + 1) + " (" + model.bodies[joint].joint_name + ")";
}

std::string joint_unit(const dynamics::Model& model, int joint, int derivative) {
  const bool prismatic = model.bodies[joint].joint_type == dynamics::JointType::kPrismatic;
  switch (derivative) {
    case 0:
      return prismatic ? "m" : "rad";
    case 1:
      return prismatic ? "m/s" : "rad/s";
    case 2:
      return prismatic ? "m/s²" : "rad/s²";
    default:
      return prismatic ? "N" : "N·m";
  }
}

std::string number(double x, int digits) {
  std::ostringstream os;
  os << std::setprecision(digits) << x;
  return os.str();
}

std::pair<std::string, std::string> distinct_numbers(double x, double y) {
  int digits = 3;
  while (digits < 17 && x != y && number(x, digits) == number(y, digits)) ++digits;
  return {number(x, digits), number(y, digits)};
}

std::string at_time(double t) {
  std::ostringstream os;
  os << "t = " << std::setprecision(4) << t << " s";
  return os.str();
}

namespace {
const char* const kQuantity[] = {"position", "velocity", "acceleration", "torque"};
}  // namespace

std::string limit_text(const dynamics::Model& model, int derivative, int joint, double z,
                       double lower, double upper, double violation, double t) {
  const dynamics::JointLimits& l = model.bodies[joint].limits;
  const double symmetric[] = {0, l.velocity, l.acceleration, l.effort};
  const double lo = derivative == 0 ? l.lower : -symmetric[derivative];
  const double hi = derivative == 0 ? l.upper : symmetric[derivative];
  const std::string u = joint_unit(model, joint, derivative);
  const std::string head =
      joint_label(model, joint) + " " + kQuantity[derivative] + " " + number(z) + " " + u;
  const double over = std::max(lo - z, z - hi);
  const std::string limit = derivative == 0
                                ? "its limits [" + number(lo) + ", " + number(hi) + "] " + u
                                : "its " + number(hi) + " " + u + " limit";
  if (over > 0) {
    return head + (derivative == 0 ? " is outside " : " exceeds ") + limit + " by " + number(over) +
           " " + u + " at " + at_time(t);
  }
  const double bound = z > 0 ? upper : lower;
  return head + " is within " + limit + " but past the planner's margin (bound " + number(bound) +
         " " + u + ") by " + number(violation) + " " + u + " at " + at_time(t);
}

std::string torque_text(const dynamics::Model& model, int joint, bool unactuated, double z,
                        double lower, double upper, double violation, double t) {
  if (unactuated) {
    return joint_label(model, joint) + " is unactuated but needs " + number(z) + " " +
           joint_unit(model, joint, 3) + " at " + at_time(t);
  }
  return limit_text(model, 3, joint, z, lower, upper, violation, t);
}

}  // namespace kinograph::planning

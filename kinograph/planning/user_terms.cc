#include "kinograph/planning/user_terms.h"

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

}  // namespace kinograph::planning

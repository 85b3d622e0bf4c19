#include "daemon/state_limits.h"

#include <spdlog/fmt/fmt.h>

#include <cmath>
#include <string>

#include "daemon/wire_strings.h"

namespace kinograph::daemon {

std::string state_beyond_limits(const messages::MeasuredState& state,
                                const dynamics::Model& model) {
  for (int j = 0; j < model.nq(); ++j) {
    const dynamics::Body& body = model.bodies[j];
    const dynamics::JointLimits& limits = body.limits;
    const double q = state.q[j];
    const double qd = state.qd[j];
    if (!std::isfinite(q) || !std::isfinite(qd)) {
      return fmt::format("joint {}: position {} or velocity {} is not finite", body.joint_name, q,
                         qd);
    }
    const double below = limits.lower - q;
    const double above = q - limits.upper;
    if (below > kStatePositionTolerance || above > kStatePositionTolerance) {
      return fmt::format(
          "joint {}: measured position {:.6g} is {:.6g} beyond its limits [{:.6g}, {:.6g}] "
          "(tolerance {:g})",
          body.joint_name, q, below > 0 ? below : above, limits.lower, limits.upper,
          kStatePositionTolerance);
    }
    if (std::abs(qd) > limits.velocity * (1 + kStateVelocityTolerance)) {
      return fmt::format(
          "joint {}: measured velocity {:.6g} is {:.6g} above its velocity limit {:.6g} "
          "(tolerance {:g} %)",
          body.joint_name, qd, std::abs(qd) - limits.velocity, limits.velocity,
          kStateVelocityTolerance * 100);
    }
  }
  return {};
}

std::string non_finite_joint(const robot_state_t& msg) {
  for (std::size_t i = 0; i < msg.joint_name.size(); ++i) {
    const double q = i < msg.position.size() ? msg.position[i] : 0.0;
    const double qd = i < msg.velocity.size() ? msg.velocity[i] : 0.0;
    if (!std::isfinite(q) || !std::isfinite(qd)) {
      return fmt::format("joint {}: position {} or velocity {} is not finite",
                         truncated(msg.joint_name[i]), q, qd);
    }
  }
  return {};
}

}  // namespace kinograph::daemon

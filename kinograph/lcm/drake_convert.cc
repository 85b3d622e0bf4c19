#include "kinograph/lcm/drake_convert.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace kinograph::messages {

Check state_from_iiwa_status(const drake::lcmt_iiwa_status& msg, const dynamics::Model& model,
                             MeasuredState& out) {
  const int n = model.nq();
  if (msg.num_joints != n) {
    return Check::fail("lcmt_iiwa_status.num_joints is " + std::to_string(msg.num_joints) +
                       ", robot " + model.name + " has " + std::to_string(n) + " joints");
  }
  auto finite = [](const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
  };
  if (!finite(msg.joint_position_measured) || !finite(msg.joint_velocity_estimated)) {
    return Check::fail(
        "lcmt_iiwa_status.joint_position_measured or joint_velocity_estimated is not finite");
  }
  MeasuredState state;
  state.utime = msg.utime;
  state.q = Eigen::Map<const Eigen::VectorXd>(msg.joint_position_measured.data(), n);
  state.qd = Eigen::Map<const Eigen::VectorXd>(msg.joint_velocity_estimated.data(), n);
  out = std::move(state);
  return {};
}

drake::lcmt_robot_plan robot_plan_from_plan(const plan_t& plan) {
  if (plan.num_steps == 0) {
    throw std::invalid_argument("plan " + std::to_string(plan.plan_id) +
                                " has no trajectory to send as lcmt_robot_plan");
  }
  if (plan.num_joints > std::numeric_limits<int16_t>::max()) {
    throw std::invalid_argument("lcmt_robot_state counts joints in int16: " +
                                std::to_string(plan.num_joints) + " joints do not fit");
  }
  drake::lcmt_robot_plan out;
  out.utime = plan.start_utime;
  out.num_states = plan.num_steps;
  out.plan.resize(plan.num_steps);
  for (int k = 0; k < plan.num_steps; ++k) {
    drake::lcmt_robot_state& knot = out.plan[k];
    knot.utime = std::llround((plan.t[k] - plan.t[0]) * 1e6);
    knot.num_joints = static_cast<int16_t>(plan.num_joints);
    knot.joint_name = plan.joint_name;
    knot.joint_position.assign(plan.q[k].begin(), plan.q[k].end());
  }
  return out;
}

}  // namespace kinograph::messages

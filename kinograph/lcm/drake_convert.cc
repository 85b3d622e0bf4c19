#include "kinograph/lcm/drake_convert.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace kinograph::messages {

std::string non_finite_iiwa_field(const drake::lcmt_iiwa_status& msg,
                                  const dynamics::Model& model) {
  // Every array, read or not: a driver sending NaN anywhere is not to be trusted for the rest.
  const std::pair<const char*, const std::vector<double>*> fields[] = {
      {"joint_position_measured", &msg.joint_position_measured},
      {"joint_velocity_estimated", &msg.joint_velocity_estimated},
      {"joint_position_commanded", &msg.joint_position_commanded},
      {"joint_position_ipo", &msg.joint_position_ipo},
      {"joint_torque_measured", &msg.joint_torque_measured},
      {"joint_torque_commanded", &msg.joint_torque_commanded},
      {"joint_torque_external", &msg.joint_torque_external}};
  for (const auto& [field, values] : fields) {
    for (std::size_t i = 0; i < values->size(); ++i) {
      if (std::isfinite((*values)[i])) continue;
      std::string joint =
          i < model.bodies.size() ? " (joint " + model.bodies[i].joint_name + ")" : "";
      return "lcmt_iiwa_status." + std::string(field) + "[" + std::to_string(i) + "]" + joint +
             " is " + std::to_string((*values)[i]);
    }
  }
  return {};
}

Check state_from_iiwa_status(const drake::lcmt_iiwa_status& msg, const dynamics::Model& model,
                             MeasuredState& out) {
  const int n = model.nq();
  if (msg.num_joints != n) {
    return Check::fail("lcmt_iiwa_status.num_joints is " + std::to_string(msg.num_joints) +
                       ", robot " + model.name + " has " + std::to_string(n) + " joints");
  }
  if (std::string bad = non_finite_iiwa_field(msg, model); !bad.empty()) return Check::fail(bad);
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

#include "kinograph/sim/rigid_body_sim.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/se3.h"

namespace kinograph::sim {
namespace {

// τ clamped to ±effort on every joint with a finite effort limit: a motor gives no more.
Eigen::VectorXd saturated(const dynamics::Model& plant, Eigen::VectorXd tau) {
  for (int j = 0; j < plant.nq(); ++j) {
    const double effort = plant.bodies[j].limits.effort;
    if (std::isfinite(effort)) tau[j] = std::clamp(tau[j], -effort, effort);
  }
  return tau;
}

}  // namespace

RigidBodySim::RigidBodySim(const dynamics::Model& plant) : plant_(plant), data_(plant) {}

Eigen::VectorXd RigidBodySim::torque(const PdGains& gains, const Setpoint& setpoint,
                                     const JointState& state) const {
  return saturated(plant_, control_torque(gains, setpoint, state.q, state.qd));
}

Eigen::VectorXd RigidBodySim::acceleration(const PdGains& gains, const Setpoint& setpoint,
                                           const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  const Eigen::VectorXd tau = saturated(plant_, control_torque(gains, setpoint, q, qd));
  return dynamics::forward_dynamics(plant_, data_, q, qd, tau);
}

void RigidBodySim::step(double dt, const PdGains& gains, const Setpoint& setpoint,
                        JointState& state) {
  // Classical RK4 on x = (q, q̇), ẋ = (q̇, q̈(q, q̇)).
  const Eigen::VectorXd& q = state.q;
  const Eigen::VectorXd& v = state.qd;
  const Eigen::VectorXd a1 = acceleration(gains, setpoint, q, v);
  const Eigen::VectorXd v2 = v + 0.5 * dt * a1;
  const Eigen::VectorXd a2 = acceleration(gains, setpoint, q + 0.5 * dt * v, v2);
  const Eigen::VectorXd v3 = v + 0.5 * dt * a2;
  const Eigen::VectorXd a3 = acceleration(gains, setpoint, q + 0.5 * dt * v2, v3);
  const Eigen::VectorXd v4 = v + dt * a3;
  const Eigen::VectorXd a4 = acceleration(gains, setpoint, q + dt * v3, v4);
  state.q = q + dt / 6 * (v + 2 * v2 + 2 * v3 + v4);
  state.qd = v + dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
  if (!state.q.allFinite() || !state.qd.allFinite()) {
    throw std::runtime_error(
        "the simulated motion diverged (a joint position or velocity is "
        "not finite): torques too large for the step");
  }
  // End stops: a joint that reached a position limit stays on it, its velocity into the stop
  // absorbed (a perfectly inelastic stop; moving away from it is free).
  for (int j = 0; j < plant_.nq(); ++j) {
    const dynamics::JointLimits& limits = plant_.bodies[j].limits;
    if (state.q[j] >= limits.upper) {
      state.q[j] = limits.upper;
      state.qd[j] = std::min(state.qd[j], 0.0);
    } else if (state.q[j] <= limits.lower) {
      state.q[j] = limits.lower;
      state.qd[j] = std::max(state.qd[j], 0.0);
    }
  }
}

dynamics::Model with_last_body_mass_change(const dynamics::Model& model, double delta_kg) {
  if (model.bodies.empty()) throw std::invalid_argument("the robot has no moving body");
  dynamics::Model out = model;
  dynamics::Body& body = out.bodies.back();
  // G = [[I_c − m [c]², m [c]], [−m [c], m 1]] about the body frame, as attach_box_payload
  // builds it: a point mass at the centre of mass adds its own such terms.
  const double mass = body.inertia(3, 3);
  if (!(mass + delta_kg > 0)) {
    throw std::invalid_argument("a payload mass change of " + std::to_string(delta_kg) +
                                " kg would leave link " + body.name + " with mass " +
                                std::to_string(mass + delta_kg) + " kg");
  }
  Eigen::Vector3d com = Eigen::Vector3d::Zero();
  if (mass > 0) {
    const Eigen::Matrix3d mc = body.inertia.block<3, 3>(0, 3);  // m [c]
    com = Eigen::Vector3d(mc(2, 1), mc(0, 2), mc(1, 0)) / mass;
  }
  const Eigen::Matrix3d C = dynamics::skew(com);
  body.inertia.block<3, 3>(0, 0) -= delta_kg * C * C;
  body.inertia.block<3, 3>(0, 3) += delta_kg * C;
  body.inertia.block<3, 3>(3, 0) -= delta_kg * C;
  body.inertia.block<3, 3>(3, 3) += delta_kg * Eigen::Matrix3d::Identity();
  return out;
}

}  // namespace kinograph::sim

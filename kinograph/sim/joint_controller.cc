#include "kinograph/sim/joint_controller.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "kinograph/dynamics/inverse_dynamics.h"

namespace kinograph::sim {

PdGains gains_for(const dynamics::Model& model, dynamics::Data& data, const Eigen::VectorXd& q,
                  double frequency_hz, double damping_ratio) {
  if (!(frequency_hz > 0) || !(damping_ratio > 0)) {
    throw std::invalid_argument("PD gains need a natural frequency and a damping ratio > 0");
  }
  const double omega = 2 * std::numbers::pi * frequency_hz;
  const Eigen::MatrixXd inertia = dynamics::mass_matrix(model, data, q);
  Eigen::VectorXd actuated(model.nq());
  for (int j = 0; j < model.nq(); ++j) actuated[j] = model.bodies[j].actuated ? 1.0 : 0.0;
  return {inertia * (omega * omega), inertia * (2 * damping_ratio * omega), actuated};
}

Eigen::VectorXd control_torque(const PdGains& gains, const Setpoint& setpoint,
                               const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  const Eigen::VectorXd tau =
      setpoint.tau + gains.kp * (setpoint.q - q) + gains.kd * (setpoint.qd - qd);
  return tau.cwiseProduct(gains.actuated);
}

Setpoint hold_setpoint(const dynamics::Model& model, dynamics::Data& data,
                       const Eigen::VectorXd& q) {
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.nq());
  return {q, zero, dynamics::rnea(model, data, q, zero, zero)};
}

}  // namespace kinograph::sim

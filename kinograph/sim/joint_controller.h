#pragma once
// The simulated robot's joint controllers: feed-forward torque plus PD feedback on the error to
// a commanded (q, q̇) setpoint, τ = τ_ff + K_p (q* − q) + K_d (q̇* − q̇), with gains shaped by
// the arm's mass matrix so that every mode near the setpoint has the same natural frequency.
#include <Eigen/Core>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/model.h"

namespace kinograph::sim {

/// What the controllers track: positions, velocities and the feed-forward torque, model order.
struct Setpoint {
  Eigen::VectorXd q, qd, tau;
};

/// PD gain matrices (N·m/rad and N·m·s/rad), joints in model order, and which joints have a
/// motor (1) or are passive (0: no torque at all, e.g. the Acrobot's shoulder).
struct PdGains {
  Eigen::MatrixXd kp, kd;
  Eigen::VectorXd actuated;
};

/// Gains K_p = ω² M(q), K_d = 2 ζ ω M(q), ω = 2πf, with M the mass matrix at q (the setpoint):
/// near q the closed loop q̈ ≈ M⁻¹ (K_p e + K_d ė) has every mode at frequency `frequency_hz`
/// and damping ratio `damping_ratio`. (Gains from M's diagonal alone leave the arm's coupled
/// modes far stiffer than ω on the iiwa, beyond what a 1 ms RK4 step integrates.)
/// Throws std::invalid_argument for a frequency or damping ratio that is not > 0.
PdGains gains_for(const dynamics::Model& model, dynamics::Data& data, const Eigen::VectorXd& q,
                  double frequency_hz, double damping_ratio);

/// The controllers' torque at state (q, q̇); 0 on passive joints.
Eigen::VectorXd control_torque(const PdGains& gains, const Setpoint& setpoint,
                               const Eigen::VectorXd& q, const Eigen::VectorXd& qd);

/// A setpoint that holds q at rest against gravity: q̇* = 0, τ_ff = RNEA(q, 0, 0) of `model`.
Setpoint hold_setpoint(const dynamics::Model& model, dynamics::Data& data,
                       const Eigen::VectorXd& q);

}  // namespace kinograph::sim

#pragma once
// The simulated robot's joint controllers: feed-forward torque plus PD feedback on the error to
// a commanded (q, q̇) setpoint, τ = τ_ff + K_p (q* − q) + K_d (q̇* − q̇), joint by joint.
#include <Eigen/Core>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/model.h"

namespace kinograph::sim {

/// What the controllers track: positions, velocities and the feed-forward torque, model order.
struct Setpoint {
  Eigen::VectorXd q, qd, tau;
};

/// Diagonal PD gains, one per joint (N·m/rad and N·m·s/rad).
struct PdGains {
  Eigen::VectorXd kp, kd;
};

/// Gains that give joint j, moving alone at configuration q, the natural frequency
/// `frequency_hz` and damping ratio `damping_ratio`: kp = M_jj ω², kd = 2 ζ M_jj ω, ω = 2πf.
/// Throws std::invalid_argument for a frequency or damping ratio that is not > 0.
PdGains gains_for(const dynamics::Model& model, dynamics::Data& data, const Eigen::VectorXd& q,
                  double frequency_hz, double damping_ratio);

/// The controllers' torque at state (q, q̇).
Eigen::VectorXd control_torque(const PdGains& gains, const Setpoint& setpoint,
                               const Eigen::VectorXd& q, const Eigen::VectorXd& qd);

/// A setpoint that holds q at rest against gravity: q̇* = 0, τ_ff = RNEA(q, 0, 0) of `model`.
Setpoint hold_setpoint(const dynamics::Model& model, dynamics::Data& data,
                       const Eigen::VectorXd& q);

}  // namespace kinograph::sim

#pragma once
// The simulated robot's body: the URDF's rigid-body dynamics integrated forward in time by
// fixed-step fourth-order Runge–Kutta, under its joint controllers.
#include <Eigen/Core>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/sim/joint_controller.h"

namespace kinograph::sim {

/// A robot's joint state.
struct JointState {
  Eigen::VectorXd q, qd;
};

/// Integrates q̈ = FD(q, q̇, τ) with τ the controllers' torque, evaluated at every RK4 stage
/// (the controllers act continuously between setpoint changes) and saturated at the plant's
/// effort limits. Position limits are end stops: after each step a joint beyond one is put back
/// on it and its velocity into the stop removed. One instance per thread.
class RigidBodySim {
 public:
  /// Borrows `plant`, which must outlive the simulator.
  explicit RigidBodySim(const dynamics::Model& plant);

  /// Advances `state` by one RK4 step of `dt` seconds under the controllers. Throws
  /// std::runtime_error when the new state is not finite (the motion diverged).
  void step(double dt, const PdGains& gains, const Setpoint& setpoint, JointState& state);
  /// The torque the motors give at `state`: the controllers', clamped to ±effort (what step()
  /// applies at the step's start).
  Eigen::VectorXd torque(const PdGains& gains, const Setpoint& setpoint,
                         const JointState& state) const;

 private:
  /// q̈ at (q, q̇) under the controllers.
  Eigen::VectorXd acceleration(const PdGains& gains, const Setpoint& setpoint,
                               const Eigen::VectorXd& q, const Eigen::VectorXd& qd);

  const dynamics::Model& plant_;
  dynamics::Data data_;
};

/// The plant with its last body's mass changed by `delta_kg` at that body's centre of mass:
/// a payload heavier (> 0) or lighter (< 0) than the model the planner and the controllers'
/// feed-forward use. Throws std::invalid_argument naming the link when its mass would not stay
/// above zero.
dynamics::Model with_last_body_mass_change(const dynamics::Model& model, double delta_kg);

}  // namespace kinograph::sim

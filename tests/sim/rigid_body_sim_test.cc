// The simulated robot's dynamics against closed forms: a PD-controlled joint without gravity is
// a damped oscillator; an arm held with its own gravity torque does not move; a step in the
// setpoint converges; a payload mass change is a point mass at the last body's centre of mass.
#include "kinograph/sim/rigid_body_sim.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/payload.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/sim/joint_controller.h"
#include "kinograph/sim/sensor_noise.h"

namespace kinograph::sim {
namespace {

// One revolute joint about the vertical: gravity exerts no torque on it.
constexpr char kTurntable[] = R"(<?xml version="1.0"?>
<robot name="turntable">
  <link name="base"/>
  <joint name="spin" type="revolute">
    <parent link="base"/><child link="arm"/>
    <axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="100" velocity="10"/>
  </joint>
  <link name="arm">
    <inertial>
      <origin xyz="0.2 0 0"/><mass value="2"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/>
    </inertial>
  </link>
</robot>)";

const planning::Scene& iiwa_desk() {
  static const planning::Scene scene =
      planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml");
  return scene;
}

// I q̈ = −k_p q − k_d q̇ from q0 at rest: q(t) = e^{−ζωt} (q0 cos ω_d t + ζω q0 / ω_d sin ω_d t).
TEST(RigidBodySim, APdJointWithoutGravityIsTheDampedOscillator) {
  const dynamics::Model model = dynamics::Model::from_urdf_string(kTurntable);
  dynamics::Data data(model);
  const double f = 2.0, zeta = 0.3, omega = 2 * std::numbers::pi * f;
  const double omega_d = omega * std::sqrt(1 - zeta * zeta);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(1);
  const PdGains gains = gains_for(model, data, zero, f, zeta);
  EXPECT_NEAR(gains.kp(0, 0), (0.03 + 2 * 0.2 * 0.2) * omega * omega, 1e-9);  // izz + m r²
  const Setpoint target{zero, zero, zero};
  RigidBodySim sim(model);
  JointState state{Eigen::VectorXd::Constant(1, 0.5), zero};
  const double dt = 1e-3;
  for (int k = 1; k <= 1500; ++k) {
    sim.step(dt, gains, target, state);
    if (k % 100 != 0) continue;
    const double t = k * dt;
    const double expected =
        std::exp(-zeta * omega * t) *
        (0.5 * std::cos(omega_d * t) + zeta * omega * 0.5 / omega_d * std::sin(omega_d * t));
    ASSERT_NEAR(state.q[0], expected, 1e-9) << "t = " << t;
  }
}

// The iiwa with its 2 kg block, held at the desk scene's start with its own gravity torque:
// nothing moves (the PD terms stay zero).
TEST(RigidBodySim, AnArmHeldWithItsGravityTorqueStaysPut) {
  const dynamics::Model& model = *iiwa_desk().problem.model;
  dynamics::Data data(model);
  const Eigen::VectorXd q0 = iiwa_desk().problem.start_q;
  const Setpoint hold = hold_setpoint(model, data, q0);
  EXPECT_GT(hold.tau.cwiseAbs().maxCoeff(), 10.0);  // gravity really is loading the arm
  const PdGains gains = gains_for(model, data, q0, 10.0, 1.0);
  RigidBodySim sim(model);
  JointState state{q0, Eigen::VectorXd::Zero(7)};
  for (int k = 0; k < 1000; ++k) sim.step(1e-3, gains, hold, state);
  EXPECT_LT((state.q - q0).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT(state.qd.cwiseAbs().maxCoeff(), 1e-8);
}

// Largest |q − q1| from `settled_s` to `end_s` after commanding q1 (with its gravity torque and
// gains at q1) to the iiwa at rest at q0.
double error_after_step(const Eigen::VectorXd& q0, const Eigen::VectorXd& q1, double settled_s,
                        double end_s) {
  const dynamics::Model& model = *iiwa_desk().problem.model;
  dynamics::Data data(model);
  const Setpoint target = hold_setpoint(model, data, q1);
  const PdGains gains = gains_for(model, data, q1, 10.0, 1.0);
  RigidBodySim sim(model);
  JointState state{q0, Eigen::VectorXd::Zero(7)};
  double worst = 0;
  for (int k = 1; k <= std::lround(end_s / 1e-3); ++k) {
    sim.step(1e-3, gains, target, state);
    if (k * 1e-3 >= settled_s) worst = std::max(worst, (state.q - q1).cwiseAbs().maxCoeff());
  }
  return worst;
}

// A 0.1 rad step on every joint settles within 1e-6 rad of the new setpoint from 1 s on (gains
// shaped by the mass matrix at the setpoint; gravity pulling away from it softens some modes, so
// the arm settles more slowly than one critically damped 10 Hz mode would).
TEST(RigidBodySim, AStepInTheSetpointConverges) {
  const Eigen::VectorXd q0 = iiwa_desk().problem.start_q;
  EXPECT_LT(error_after_step(q0, q0.array() + 0.1, 1.0, 1.5), 1e-6);
}

// Across the workspace (the desk scene's start to its goal, up to 1.28 rad on a joint) the loop
// stays stable and settles, within 1e-6 rad from 1.5 s on.
TEST(RigidBodySim, AStepAcrossTheWorkspaceConverges) {
  const auto& scene = iiwa_desk();
  EXPECT_LT(error_after_step(scene.problem.start_q, scene.problem.goal.q, 1.5, 2.5), 1e-6);
}

// Gains far too stiff for a 1 ms step (a 1 kHz loop) make the motion diverge: the simulator
// says so instead of carrying on with NaN. (Motors without effort limits: saturated ones would
// keep the torques, and the motion, bounded.)
TEST(RigidBodySim, ADivergingMotionIsReportedNotContinued) {
  dynamics::Model model = *iiwa_desk().problem.model;
  for (auto& body : model.bodies) body.limits.effort = std::numeric_limits<double>::infinity();
  dynamics::Data data(model);
  const Eigen::VectorXd q0 = iiwa_desk().problem.start_q;
  const Setpoint target = hold_setpoint(model, data, q0.array() + 0.1);
  const PdGains gains = gains_for(model, data, q0, 1000.0, 1.0);
  RigidBodySim sim(model);
  JointState state{q0, Eigen::VectorXd::Zero(7)};
  EXPECT_THROW(
      {
        for (int k = 0; k < 1000; ++k) sim.step(1e-3, gains, target, state);
      },
      std::runtime_error);
}

// A setpoint far away asks for more torque than the motor has: it gives exactly its effort
// limit, so from rest the joint accelerates at effort / inertia (constant over the step).
TEST(RigidBodySim, TorqueSaturatesAtTheEffortLimit) {
  const dynamics::Model model = dynamics::Model::from_urdf_string(kTurntable);  // effort 100
  dynamics::Data data(model);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(1);
  const PdGains gains = gains_for(model, data, zero, 10.0, 1.0);
  const Setpoint far{Eigen::VectorXd::Constant(1, 2.5), zero, zero};
  RigidBodySim sim(model);
  JointState state{zero, zero};
  EXPECT_GT(control_torque(gains, far, state.q, state.qd)[0], 100.0);  // what the PD asks
  EXPECT_EQ(sim.torque(gains, far, state)[0], 100.0);                  // what the motor gives
  const double inertia = 0.03 + 2 * 0.2 * 0.2, dt = 1e-3;
  sim.step(dt, gains, far, state);
  EXPECT_NEAR(state.qd[0], 100.0 / inertia * dt, 1e-12);
  EXPECT_NEAR(state.q[0], 100.0 / inertia * dt * dt / 2, 1e-12);
}

// A setpoint beyond a position limit drives the joint into its end stop: it stops there, on the
// limit exactly and at rest, and leaves it freely when the setpoint comes back.
TEST(RigidBodySim, APositionLimitIsAnEndStop) {
  const dynamics::Model model = dynamics::Model::from_urdf_string(kTurntable);  // limits ±3
  dynamics::Data data(model);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(1);
  const PdGains gains = gains_for(model, data, zero, 2.0, 1.0);
  RigidBodySim sim(model);
  JointState state{Eigen::VectorXd::Constant(1, 2.5), zero};
  const Setpoint beyond{Eigen::VectorXd::Constant(1, 3.5), zero, zero};
  double highest = 0;
  bool reached = false;
  for (int k = 0; k < 2000; ++k) {
    sim.step(1e-3, gains, beyond, state);
    highest = std::max(highest, state.q[0]);
    if (state.q[0] == 3.0) {
      reached = true;
      EXPECT_EQ(state.qd[0], 0.0) << k;
    }
  }
  EXPECT_TRUE(reached);
  EXPECT_EQ(highest, 3.0);
  const Setpoint back{Eigen::VectorXd::Constant(1, 2.0), zero, zero};
  for (int k = 0; k < 2000; ++k) sim.step(1e-3, gains, back, state);
  EXPECT_NEAR(state.q[0], 2.0, 1e-3);
}

// The mass change is a point mass at the last body's centre of mass: the same as a box of no
// size attached there through the dynamics module's own payload function.
TEST(MassChange, IsAPointMassAtTheLastBodysCentreOfMass) {
  const dynamics::Model& model = *iiwa_desk().problem.model;
  const dynamics::Body& last = model.bodies.back();
  const double mass = last.inertia(3, 3);
  const Eigen::Matrix3d mc = last.inertia.block<3, 3>(0, 3);
  const Eigen::Vector3d com = Eigen::Vector3d(mc(2, 1), mc(0, 2), mc(1, 0)) / mass;
  const dynamics::Model heavier = with_last_body_mass_change(model, 0.2);
  EXPECT_NEAR(heavier.bodies.back().inertia(3, 3), mass + 0.2, 1e-12);
  EXPECT_NEAR(heavier.total_mass(), model.total_mass() + 0.2, 1e-12);
  Eigen::Isometry3d at_com = Eigen::Isometry3d::Identity();
  at_com.translation() = com;
  const dynamics::Model reference =
      dynamics::attach_box_payload(model, last.name, 0.2, Eigen::Vector3d::Zero(), at_com);
  dynamics::Data d1(heavier), d2(reference);
  const Eigen::VectorXd q = iiwa_desk().problem.start_q;
  const Eigen::VectorXd qd = Eigen::VectorXd::LinSpaced(7, -0.5, 0.5);
  const Eigen::VectorXd qdd = Eigen::VectorXd::LinSpaced(7, 1.0, -1.0);
  const Eigen::VectorXd tau1 = dynamics::rnea(heavier, d1, q, qd, qdd);
  const Eigen::VectorXd tau2 = dynamics::rnea(reference, d2, q, qd, qdd);
  EXPECT_LT((tau1 - tau2).cwiseAbs().maxCoeff(), 1e-10);
  dynamics::Data d0(model);
  EXPECT_GT((tau1 - dynamics::rnea(model, d0, q, qd, qdd)).cwiseAbs().maxCoeff(), 0.1);
}

TEST(MassChange, ALinkLeftWithoutMassIsRefusedByName) {
  const dynamics::Model& model = *iiwa_desk().problem.model;
  try {
    with_last_body_mass_change(model, -100.0);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("link " + model.bodies.back().name), std::string::npos)
        << e.what();
  }
}

// The Acrobot's shoulder has no motor: whatever the setpoint and the error, it gets no torque.
TEST(Gains, APassiveJointGetsNoTorque) {
  const planning::Scene acrobot = planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) +
                                                       "/robots/scenes/acrobot_swingup.yaml");
  const dynamics::Model& model = *acrobot.problem.model;
  ASSERT_FALSE(model.bodies[0].actuated);
  dynamics::Data data(model);
  const Eigen::Vector2d q(0.3, -0.2);
  const PdGains gains = gains_for(model, data, q, 10.0, 1.0);
  const Setpoint setpoint{Eigen::Vector2d(1.0, 1.0), Eigen::Vector2d(0.5, 0.5),
                          Eigen::Vector2d(2.0, 3.0)};
  const Eigen::VectorXd tau = control_torque(gains, setpoint, q, Eigen::Vector2d::Zero());
  EXPECT_EQ(tau[0], 0.0);
  EXPECT_GT(std::abs(tau[1]), 3.0);
}

TEST(Gains, NeedAPositiveFrequencyAndDampingRatio) {
  const dynamics::Model model = dynamics::Model::from_urdf_string(kTurntable);
  dynamics::Data data(model);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(1);
  EXPECT_THROW(gains_for(model, data, zero, 0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(gains_for(model, data, zero, 10.0, -1.0), std::invalid_argument);
}

// Same seed, same noise; the deviation is the one asked for; zero noise is exact.
TEST(SensorNoise, IsSeededAndHasTheDeviationAskedFor) {
  auto draws = [](unsigned seed, double std) {
    SensorNoise noise(std, 2 * std, seed);
    Eigen::VectorXd q = Eigen::VectorXd::Zero(20000), qd = Eigen::VectorXd::Zero(20000);
    noise.apply(q, qd);
    return std::pair{q, qd};
  };
  const auto [q1, qd1] = draws(7, 1e-3);
  const auto [q2, qd2] = draws(7, 1e-3);
  const auto [q3, qd3] = draws(8, 1e-3);
  EXPECT_EQ(q1, q2);
  EXPECT_EQ(qd1, qd2);
  EXPECT_NE(q1, q3);
  const double std_q = std::sqrt(q1.squaredNorm() / q1.size());
  const double std_qd = std::sqrt(qd1.squaredNorm() / qd1.size());
  EXPECT_NEAR(std_q, 1e-3, 3e-5);
  EXPECT_NEAR(std_qd, 2e-3, 6e-5);
  EXPECT_EQ(draws(7, 0.0).first, Eigen::VectorXd::Zero(20000));
  EXPECT_THROW(SensorNoise(-1.0, 0.0, 1), std::invalid_argument);
}

}  // namespace
}  // namespace kinograph::sim

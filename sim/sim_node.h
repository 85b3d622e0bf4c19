#pragma once
// `kinograph sim`'s core: a simulated robot on an LCM network. It integrates the robot's
// forward dynamics (kinograph/sim, RK4 at 1 kHz) under feed-forward + PD joint controllers that
// track the latest joint_command_t from <PREFIX>_COMMAND (held until the next one), and
// publishes robot_state_t on <PREFIX>_STATE at 200 Hz on its own clock, which may run slower
// than the wall clock (sim time). It measures how well the robot tracks its setpoints.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "kinograph/lcm/message_convert.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/sim/joint_controller.h"
#include "kinograph/sim/rigid_body_sim.h"
#include "kinograph/sim/sensor_noise.h"

namespace lcm {
class LCM;
class ReceiveBuffer;
class Subscription;
}  // namespace lcm

namespace kinograph::sim {

/// Options of a SimNode; defaults give a real-time robot on the local LCM network.
struct SimNodeOptions {
  /// LCM provider URL; empty = $LCM_DEFAULT_URL, else LCM's default multicast group.
  std::string lcm_url;
  /// Channel prefix (IIWA for IIWA_STATE, IIWA_COMMAND); empty = the robot name upper-cased.
  std::string channel_prefix;
  /// Wall-clock seconds per simulated second: 10 runs the robot ten times slower than real time.
  double slowdown = 1.0;
  /// The robot's clock at the start (µs); -1 = the wall clock (epoch) at the start.
  int64_t start_utime = -1;
  /// Simulated seconds to run; 0 = until stopped.
  double duration_s = 0;
  /// Mass added to the last link at its centre of mass (kg; negative = lighter): a payload the
  /// planner's and the controllers' model get wrong.
  double payload_mass_error_kg = 0;
  /// Standard deviations of the published positions (rad) and velocities (rad/s).
  double position_noise = 0, velocity_noise = 0;
  /// Seed of the sensor noise.
  unsigned seed = 1;
  /// Channel on which to publish Drake's lcmt_iiwa_status as well (e.g. "IIWA_STATUS"); empty =
  /// none.
  std::string iiwa_status_channel;
};

/// Tracking error |q* − q| (largest over the joints, true state) sampled at every published
/// state: its largest value and RMS over a run, in rad.
struct TrackingStats {
  double max = 0;
  double sum_sq = 0;
  long samples = 0;
  /// Root mean square of the samples (0 without samples).
  double rms() const;
  /// Adds one sample.
  void add(double error);
};

/// The simulated robot's node: plant, controllers, clock and LCM.
class SimNode {
 public:
  static constexpr double kStepS = 1e-3;        ///< RK4 step (1 kHz)
  static constexpr int kStepsPerState = 5;      ///< a state every 5 ms (200 Hz)
  static constexpr double kPdFrequencyHz = 10;  ///< natural frequency of the PD loop's modes
  static constexpr double kDampingRatio = 1;    ///< critically damped
  static constexpr double kLogPeriodS = 1;      ///< tracking error logged every simulated second

  /// Starts at the scene's start state, holding it against gravity until the first command.
  /// Throws std::invalid_argument for options out of range (naming the option) and
  /// std::runtime_error when LCM cannot start. `shared`: an LCM instance to use instead of
  /// opening options.lcm_url (in-process tests); it must outlive the node.
  SimNode(planning::Scene scene, SimNodeOptions options, lcm::LCM* shared = nullptr);
  ~SimNode();
  SimNode(const SimNode&) = delete;
  SimNode& operator=(const SimNode&) = delete;

  /// Simulates, paced by the wall clock, until `stop` or the duration is reached. Throws
  /// std::runtime_error, with the simulated time, if the motion diverges.
  void run(const std::atomic<bool>& stop);

  /// Full channel name for a suffix, e.g. channel("STATE") = "IIWA_STATE".
  std::string channel(const std::string& suffix) const;
  /// Tracking error over the whole run so far.
  const TrackingStats& tracking() const { return total_; }
  /// Commands received and refused since the start.
  long commands_received() const { return commands_; }
  long commands_rejected() const { return rejected_; }

 private:
  void on_command(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void publish_state(int64_t utime);
  double tracking_error() const;

  planning::Scene scene_;
  SimNodeOptions options_;
  messages::RobotIdentity identity_;
  dynamics::Model plant_;  // the scene's model with the payload error
  std::unique_ptr<dynamics::Data> data_;
  std::unique_ptr<RigidBodySim> sim_;
  PdGains gains_;
  Setpoint setpoint_;
  JointState state_;
  SensorNoise noise_;
  std::unique_ptr<lcm::LCM> owned_lcm_;
  lcm::LCM* lcm_ = nullptr;
  lcm::Subscription* subscription_ = nullptr;
  TrackingStats total_, window_;
  long commands_ = 0, rejected_ = 0;
};

}  // namespace kinograph::sim

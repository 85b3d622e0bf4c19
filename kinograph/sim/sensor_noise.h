#pragma once
// Measurement noise of the simulated robot's joint sensors: zero-mean Gaussian, seeded, so that
// a run with the same seed measures the same noise.
#include <Eigen/Core>
#include <random>

namespace kinograph::sim {

/// Adds independent Gaussian noise to measured positions and velocities.
class SensorNoise {
 public:
  /// Standard deviations in rad (or m) and rad/s (or m/s); 0 = exact. Throws
  /// std::invalid_argument for a negative or non-finite deviation.
  SensorNoise(double position_std, double velocity_std, unsigned seed);
  /// Adds one draw of noise to each entry of q and qd.
  void apply(Eigen::VectorXd& q, Eigen::VectorXd& qd);

 private:
  double position_std_, velocity_std_;
  std::mt19937_64 engine_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace kinograph::sim

#include "kinograph/sim/sensor_noise.h"

#include <cmath>
#include <stdexcept>

namespace kinograph::sim {

SensorNoise::SensorNoise(double position_std, double velocity_std, unsigned seed)
    : position_std_(position_std), velocity_std_(velocity_std), engine_(seed) {
  if (!(std::isfinite(position_std) && position_std >= 0 && std::isfinite(velocity_std) &&
        velocity_std >= 0)) {
    throw std::invalid_argument("sensor noise deviations must be finite and >= 0");
  }
}

void SensorNoise::apply(Eigen::VectorXd& q, Eigen::VectorXd& qd) {
  for (Eigen::Index j = 0; j < q.size(); ++j) q[j] += position_std_ * normal_(engine_);
  for (Eigen::Index j = 0; j < qd.size(); ++j) qd[j] += velocity_std_ * normal_(engine_);
}

}  // namespace kinograph::sim

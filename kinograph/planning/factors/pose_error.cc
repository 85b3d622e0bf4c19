#include "kinograph/planning/factors/pose_error.h"

#include <algorithm>
#include <cmath>

namespace kinograph::planning {

PoseError pose_error(const Eigen::Isometry3d& pose, const Eigen::Isometry3d& target) {
  PoseError e;
  e.position = (pose.translation() - target.translation()).norm();
  const Eigen::Matrix3d R = target.linear().transpose() * pose.linear();
  const double c = std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0);
  // atan2 of sin and cos keeps precision near 0 and π.
  const Eigen::Vector3d w(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  e.rotation = std::atan2(0.5 * w.norm(), c);
  return e;
}

}  // namespace kinograph::planning

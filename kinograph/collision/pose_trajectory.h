#pragma once

#include <Eigen/Geometry>
#include <vector>

namespace kinograph::collision {

// The pose of a moving obstacle over time (e.g. a link of a neighbouring robot's published
// plan): samples at strictly increasing times, linear in position and slerp in rotation
// between samples, held constant before the first and after the last.
class PoseTrajectory {
 public:
  // No samples: empty() is true and the owner's static pose applies.
  PoseTrajectory() = default;
  // Throws std::invalid_argument when the sizes differ, there are no samples, or the times
  // are not finite and strictly increasing.
  PoseTrajectory(std::vector<double> times, std::vector<Eigen::Isometry3d> poses);

  // Interpolated pose at time t (seconds, the same clock as the samples). Allocates nothing.
  Eigen::Isometry3d at(double t) const;
  // True when there are no samples.
  bool empty() const { return times_.empty(); }
  // Sample times, strictly increasing.
  const std::vector<double>& times() const { return times_; }
  // Sampled poses, one per time.
  const std::vector<Eigen::Isometry3d>& poses() const { return poses_; }

 private:
  std::vector<double> times_;
  std::vector<Eigen::Isometry3d> poses_;
  std::vector<Eigen::Quaterniond> rotations_;  // poses_' rotations, made once for slerp
};

}  // namespace kinograph::collision

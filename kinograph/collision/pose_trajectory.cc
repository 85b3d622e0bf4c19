#include "kinograph/collision/pose_trajectory.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace kinograph::collision {

PoseTrajectory::PoseTrajectory(std::vector<double> times, std::vector<Eigen::Isometry3d> poses)
    : times_(std::move(times)), poses_(std::move(poses)) {
  if (times_.size() != poses_.size()) {
    throw std::invalid_argument("pose trajectory: " + std::to_string(times_.size()) +
                                " times but " + std::to_string(poses_.size()) + " poses");
  }
  if (times_.empty()) throw std::invalid_argument("pose trajectory: no samples");
  for (size_t i = 0; i < times_.size(); ++i) {
    if (!std::isfinite(times_[i]) || (i > 0 && !(times_[i] > times_[i - 1]))) {
      throw std::invalid_argument("pose trajectory: time " + std::to_string(i) + " (" +
                                  std::to_string(times_[i]) +
                                  ") is not finite and after the previous one");
    }
  }
  rotations_.reserve(poses_.size());
  for (const Eigen::Isometry3d& T : poses_) rotations_.emplace_back(T.rotation());
}

Eigen::Isometry3d PoseTrajectory::at(double t) const {
  if (times_.empty()) return Eigen::Isometry3d::Identity();
  if (!(t > times_.front())) return poses_.front();
  if (!(t < times_.back())) return poses_.back();
  // First sample strictly after t; its predecessor is at or before t.
  const size_t hi = std::upper_bound(times_.begin(), times_.end(), t) - times_.begin();
  const size_t lo = hi - 1;
  const double s = (t - times_[lo]) / (times_[hi] - times_[lo]);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotations_[lo].slerp(s, rotations_[hi]).toRotationMatrix();
  T.translation() = (1 - s) * poses_[lo].translation() + s * poses_[hi].translation();
  return T;
}

}  // namespace kinograph::collision

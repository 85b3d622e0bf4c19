#pragma once
// Distance between two world poses, split into position (m) and rotation angle (rad); shared by
// the pose factors and the validator.
#include <Eigen/Geometry>

namespace kinograph::planning {

/// Position distance ‖p − p*‖ (m) and rotation angle of R*ᵀR (rad, in [0, π]).
struct PoseError {
  double position = 0;
  double rotation = 0;
};

/// The error of `pose` with respect to `target`.
PoseError pose_error(const Eigen::Isometry3d& pose, const Eigen::Isometry3d& target);

}  // namespace kinograph::planning

#pragma once
// Where a robot stands: its root link placed at a pose in the world (several arms in one cell).
#include <Eigen/Geometry>

#include "kinograph/dynamics/model.h"

namespace kinograph::dynamics {

/// Returns a copy of `model` whose root link stands at `world_from_base` in the world: the bodies
/// on the root, the root's frames and its geometry move with it; gravity stays the same world
/// vector, so a tilted base feels gravity tilted. Throws std::invalid_argument when the pose is
/// not finite or its rotation is not orthonormal (to 1e-9).
Model place_base(const Model& model, const Eigen::Isometry3d& world_from_base);

/// True when the pose is the identity to 1e-12 (a robot standing at the world origin).
bool is_identity_pose(const Eigen::Isometry3d& pose);

}  // namespace kinograph::dynamics

#pragma once
// A robot model's identifier in heartbeats, so that a neighbour's daemon can tell that the robot
// it hears is the one its scene describes (same URDF, same payload and limits).
#include <Eigen/Geometry>
#include <string>

#include "kinograph/dynamics/model.h"

namespace kinograph::fleet {

/// "NAME:HHHHHHHHHHHHHHHH": the URDF robot name and a 64-bit FNV-1a hash (hex) of what other
/// robots depend on — bodies, joints, limits and collision geometry, numbers rounded to 1e-9 —
/// so the same URDF gives the same id in every process and on every host.
std::string model_id(const dynamics::Model& model);

/// Why a heartbeat's base pose is not `expected` (beyond 1 mm or 1 mrad), or empty.
std::string base_mismatch(const Eigen::Isometry3d& expected, const Eigen::Isometry3d& heard);

}  // namespace kinograph::fleet

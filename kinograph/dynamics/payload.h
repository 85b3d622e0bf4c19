#pragma once
// Rigid payloads carried by the robot (e.g. the iiwa's block at the flange).
#include <Eigen/Geometry>
#include <string>

#include "kinograph/dynamics/model.h"

namespace kinograph::dynamics {

/// Returns a copy of `model` carrying a solid box of uniform density: its inertia joins the
/// body owning `frame`, a box joins the collision and visual geometry, and a frame named
/// "payload" (or "payload_<n>" if taken) marks the box centre. `offset` places the box centre
/// in `frame`. Throws std::out_of_range for an unknown frame, std::invalid_argument for a
/// negative mass or size.
Model attach_box_payload(const Model& model, const std::string& frame, double mass,
                         const Eigen::Vector3d& size, const Eigen::Isometry3d& offset);

}  // namespace kinograph::dynamics

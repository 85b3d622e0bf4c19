#include "kinograph/dynamics/base_placement.h"

#include <stdexcept>

namespace kinograph::dynamics {

Model place_base(const Model& model, const Eigen::Isometry3d& world_from_base) {
  const Eigen::Matrix4d& m = world_from_base.matrix();
  if (!m.allFinite()) throw std::invalid_argument("the base pose is not finite");
  const Eigen::Matrix3d r = world_from_base.linear();
  if (!(r.transpose() * r).isApprox(Eigen::Matrix3d::Identity(), 1e-9) || r.determinant() <= 0) {
    throw std::invalid_argument("the base pose's rotation is not a rotation");
  }
  Model placed = model;
  // The root link's frame was the world frame; everything expressed in it moves.
  for (Body& body : placed.bodies) {
    if (body.parent < 0) body.parent_to_joint = world_from_base * body.parent_to_joint;
  }
  for (Frame& frame : placed.frames) {
    if (frame.body < 0) frame.placement = world_from_base * frame.placement;
  }
  for (std::vector<Geometry>* list : {&placed.collision, &placed.visual}) {
    for (Geometry& g : *list) {
      if (g.body < 0) g.origin = world_from_base * g.origin;
    }
  }
  return placed;
}

bool is_identity_pose(const Eigen::Isometry3d& pose) {
  return (pose.matrix() - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff() < 1e-12;
}

}  // namespace kinograph::dynamics

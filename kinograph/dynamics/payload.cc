#include "kinograph/dynamics/payload.h"

#include <stdexcept>

namespace kinograph::dynamics {

Model attach_box_payload(const Model& model, const std::string& frame, double mass,
                         const Eigen::Vector3d& size, const Eigen::Isometry3d& offset) {
  if (!(mass >= 0) || !(size.minCoeff() >= 0)) {
    throw std::invalid_argument("attach_box_payload: mass and size must be >= 0");
  }
  Model out = model;
  const Frame& f = model.frames.at(model.frame_index(frame));
  const Eigen::Isometry3d pose = f.placement * offset;  // box centre in the body frame

  if (f.body >= 0) {
    // Solid cuboid about its centre: m/12 (b² + c², a² + c², a² + b²), rotated into the body.
    const Eigen::Vector3d s2 = size.cwiseProduct(size);
    const Eigen::Vector3d d(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y());
    const Eigen::Matrix3d Ic =
        pose.linear() * (mass / 12.0 * d).asDiagonal() * pose.linear().transpose();
    const Eigen::Matrix3d C = skew(pose.translation());
    Matrix6 G;
    G << Ic - mass * C * C, mass * C, -mass * C, mass * Eigen::Matrix3d::Identity();
    out.bodies[f.body].inertia += G;
  }

  std::string name = "payload";
  for (int n = 2; [&] {
         for (const Frame& g : out.frames)
           if (g.name == name) return true;
         return false;
       }();
       ++n) {
    name = "payload_" + std::to_string(n);
  }
  out.frames.push_back({name, f.body, pose});

  Geometry box;
  box.shape = Geometry::Shape::kBox;
  box.size = size;
  box.origin = pose;
  box.body = f.body;
  box.link_name = name;
  box.rgba << 0.8, 0.5, 0.2, 1.0;
  out.collision.push_back(box);
  out.visual.push_back(box);
  return out;
}

}  // namespace kinograph::dynamics

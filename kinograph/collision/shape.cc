#include "kinograph/collision/shape.h"

#include <utility>

namespace kinograph::collision {

Shape Shape::sphere(double radius) {
  Shape s;
  s.kind = ShapeKind::kSphere;
  s.size = Eigen::Vector3d(radius, 0, 0);
  return s;
}

Shape Shape::box(double x, double y, double z) {
  Shape s;
  s.kind = ShapeKind::kBox;
  s.size = Eigen::Vector3d(x, y, z);
  return s;
}

Shape Shape::cylinder(double radius, double length) {
  Shape s;
  s.kind = ShapeKind::kCylinder;
  s.size = Eigen::Vector3d(radius, length, 0);
  return s;
}

Shape Shape::capsule(double radius, double length) {
  Shape s;
  s.kind = ShapeKind::kCapsule;
  s.size = Eigen::Vector3d(radius, length, 0);
  return s;
}

Shape Shape::mesh(std::string path, const Eigen::Vector3d& scale) {
  Shape s;
  s.kind = ShapeKind::kMesh;
  s.mesh_path = std::move(path);
  s.mesh_scale = scale;
  return s;
}

}  // namespace kinograph::collision

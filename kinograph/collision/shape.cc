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

Shape shape_of(const dynamics::Geometry& g) {
  Shape s;
  switch (g.shape) {
    case dynamics::Geometry::Shape::kSphere:
      s.kind = ShapeKind::kSphere;
      break;
    case dynamics::Geometry::Shape::kBox:
      s.kind = ShapeKind::kBox;
      break;
    case dynamics::Geometry::Shape::kCylinder:
      s.kind = ShapeKind::kCylinder;
      break;
    case dynamics::Geometry::Shape::kCapsule:
      s.kind = ShapeKind::kCapsule;
      break;
    case dynamics::Geometry::Shape::kMesh:
      s.kind = ShapeKind::kMesh;
      break;
  }
  s.size = g.size;
  s.mesh_path = g.mesh_path;
  s.mesh_scale = g.mesh_scale;
  return s;
}

}  // namespace kinograph::collision

#include "kinograph/collision/shape.h"

#include <cmath>
#include <sstream>
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

namespace {

// Why `value` (the dimension `what` of a shape) is outside [min, max], or empty.
std::string dimension_error(const std::string& what, double value, double min, double max,
                            const std::string& unit = " m") {
  if (std::isfinite(value) && value >= min && value <= max) return {};
  std::ostringstream out;
  out << what << " is " << value << unit;
  if (!std::isfinite(value)) {
    out << ", not a finite number";
  } else if (value < min) {
    out << ", below the " << min << unit << " the collision engine measures faithfully";
  } else {
    out << ", beyond the " << max << unit << " the collision engine measures faithfully";
  }
  return out.str();
}

}  // namespace

std::string range_error(const Shape& shape) {
  const Eigen::Vector3d& s = shape.size;
  std::string e;
  const auto check = [&](const std::string& what, double value, double min, double max,
                         const std::string& unit = " m") {
    if (e.empty()) e = dimension_error(what, value, min, max, unit);
  };
  switch (shape.kind) {
    case ShapeKind::kSphere:
      check("sphere radius", s.x(), kMinShapeDimension, kMaxShapeDimension);
      break;
    case ShapeKind::kBox:
      check("box side x", s.x(), kMinShapeDimension, kMaxShapeDimension);
      check("box side y", s.y(), kMinShapeDimension, kMaxShapeDimension);
      check("box side z", s.z(), kMinShapeDimension, kMaxShapeDimension);
      break;
    case ShapeKind::kCylinder:
      check("cylinder radius", s.x(), kMinShapeDimension, kMaxCylinderDimension);
      check("cylinder length", s.y(), kMinShapeDimension, kMaxCylinderDimension);
      break;
    case ShapeKind::kCapsule:
      check("capsule radius", s.x(), kMinShapeDimension, kMaxShapeDimension);
      // A capsule of length 0 is a sphere.
      if (s.y() != 0) check("capsule length", s.y(), kMinShapeDimension, kMaxShapeDimension);
      break;
    case ShapeKind::kMesh:
      check("mesh scale x", shape.mesh_scale.x(), kMinShapeDimension, kMaxMeshScale, "");
      check("mesh scale y", shape.mesh_scale.y(), kMinShapeDimension, kMaxMeshScale, "");
      check("mesh scale z", shape.mesh_scale.z(), kMinShapeDimension, kMaxMeshScale, "");
      break;
  }
  return e;
}

std::string position_range_error(const Eigen::Vector3d& position) {
  for (int i = 0; i < 3; ++i) {
    const double c = position[i];
    if (std::isfinite(c) && std::abs(c) <= kMaxObstacleCoordinate) continue;
    std::ostringstream out;
    out << "position "
        << "xyz"[i] << " is " << c << " m";
    if (std::isfinite(c)) {
      out << ", beyond the " << kMaxObstacleCoordinate << " m limit";
    } else {
      out << ", not a finite number";
    }
    return out.str();
  }
  return {};
}

}  // namespace kinograph::collision

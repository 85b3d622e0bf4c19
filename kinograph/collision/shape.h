#pragma once

#include <Eigen/Core>
#include <string>

#include "kinograph/dynamics/geometry.h"

namespace kinograph::collision {

// Kinds of convex solid a robot link or an obstacle can be made of.
enum class ShapeKind { kSphere, kBox, kCylinder, kCapsule, kMesh };

// A convex solid in its own frame, with the same size conventions as the URDF collision
// geometry in dynamics::Geometry: sphere (r,0,0); box full extents (x,y,z); cylinder and
// capsule (radius, length, 0) along local z, a capsule's length between its cap centres;
// a mesh is replaced by the convex hull of its vertices (scaled by mesh_scale).
struct Shape {
  ShapeKind kind = ShapeKind::kSphere;
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  std::string mesh_path;
  Eigen::Vector3d mesh_scale = Eigen::Vector3d::Ones();

  // A sphere of the given radius about the origin.
  static Shape sphere(double radius);
  // A box centred at the origin with full extents (x, y, z).
  static Shape box(double x, double y, double z);
  // A cylinder along z centred at the origin.
  static Shape cylinder(double radius, double length);
  // A capsule along z centred at the origin; length is between the two cap centres.
  static Shape capsule(double radius, double length);
  // The convex hull of a mesh file's vertices (any format assimp reads), scaled per axis.
  static Shape mesh(std::string path, const Eigen::Vector3d& scale = Eigen::Vector3d::Ones());
};

// The solid of one robot collision geometry from the Model (its pose is kept separately).
Shape shape_of(const dynamics::Geometry& geometry);

// Dimensions (m) within which Bullet's GJK/EPA measures signed distances faithfully: within
// 1 µm of the closed form for a 5 cm sphere anywhere in or around the solid (within the
// solid's thickness where the sphere swallows its cross-section;
// tests/collision/shape_range_test.cc). Beyond them it mis-measures, up to calling a robot
// inside a huge box collision-free (docs/reliability.md), so such shapes are refused.
inline constexpr double kMinShapeDimension = 1e-4;   // every radius, length, side, scale
inline constexpr double kMaxShapeDimension = 1e4;    // box sides, sphere and capsule
inline constexpr double kMaxCylinderDimension = 10;  // cylinder radius and length
inline constexpr double kMaxMeshScale = 1e2;         // per-axis scale of a mesh (no unit)
// Largest |coordinate| (m) of an obstacle's position: keeps every distance's rounding far
// below a micrometre.
inline constexpr double kMaxObstacleCoordinate = 1e5;

// Empty when every dimension of `shape` is finite and within the faithful range of its kind;
// otherwise why not, naming the dimension, its value and the limit, e.g. "box side x is 1e+80
// m, beyond the 10000 m the collision engine measures faithfully".
std::string range_error(const Shape& shape);

// Empty when every coordinate of `position` is finite and within kMaxObstacleCoordinate;
// otherwise why not.
std::string position_range_error(const Eigen::Vector3d& position);

}  // namespace kinograph::collision

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

}  // namespace kinograph::collision

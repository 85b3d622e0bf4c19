#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>

#include "kinograph/collision/shape.h"

class btConvexShape;

namespace kinograph::collision {

// A Bullet (double precision) convex shape made once from a Shape, with a bounding sphere
// for cheap culling. Margins are chosen so the Bullet shape is exactly the described solid:
// spheres and capsules carry their radius as margin; boxes, cylinders and mesh hulls have
// margin 0 (a box's default 0.04 margin rounds its edges; a hull's margin would inflate it).
// A mesh's hull is read and computed once per process for each file (path, size, modification
// time) and scale, and shared, read-only, by every shape made from it since.
class ConvexShape {
 public:
  // Builds the Bullet shape. Throws std::invalid_argument for non-positive sizes and for a
  // mesh file that cannot be read or has fewer than 4 vertices (the message names the file).
  explicit ConvexShape(const Shape& shape);
  ~ConvexShape();
  ConvexShape(ConvexShape&&) noexcept;
  ConvexShape& operator=(ConvexShape&&) noexcept;
  ConvexShape(const ConvexShape&) = delete;
  ConvexShape& operator=(const ConvexShape&) = delete;

  // The description this shape was built from.
  const Shape& shape() const { return shape_; }
  // Centre of the bounding sphere in the shape's own frame.
  const Eigen::Vector3d& bound_center() const { return bound_center_; }
  // Radius of a sphere about bound_center() that contains the whole solid.
  double bound_radius() const { return bound_radius_; }
  // A world-axis-aligned box containing the shape at this pose (Bullet's, conservative).
  void world_aabb(const Eigen::Isometry3d& pose, Eigen::Vector3d& lo, Eigen::Vector3d& hi) const;
  // The underlying Bullet shape (double precision build).
  const btConvexShape& bullet() const { return *bullet_; }

 private:
  Shape shape_;
  std::shared_ptr<const btConvexShape> bullet_;
  Eigen::Vector3d bound_center_ = Eigen::Vector3d::Zero();
  double bound_radius_ = 0;
};

// Call once anywhere: it references an out-of-line btScalar function of Bullet, so a build
// compiled for double but linked against the float libraries (or the reverse) fails to link
// instead of crashing at run time (docs/build.md).
void bullet_precision_link_guard();

// How many mesh hulls this process has read and computed (each file and scale once while the
// file stays the same).
int mesh_hulls_computed();

}  // namespace kinograph::collision

#pragma once

#include <Eigen/Geometry>

#include "kinograph/collision/pose_trajectory.h"
#include "kinograph/collision/shape.h"

namespace kinograph::collision {

// Most obstacles one world (a scene's fixed ones plus those sent over LCM) may hold: the
// planner's collision factors, memory and time per plan grow with the count.
inline constexpr int kMaxObstacles = 1024;

// A solid in the robot's workspace: a fixed body (desk, wall) or, with a trajectory, a moving
// one (a neighbouring robot's link along its published plan). The id is the caller's handle.
struct Obstacle {
  int id = 0;
  Shape shape;
  // World pose of the shape's frame; used when the trajectory is empty.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  // World pose over time; when non-empty it replaces `pose`.
  PoseTrajectory trajectory;

  // World pose at time t (seconds).
  Eigen::Isometry3d pose_at(double t) const { return trajectory.empty() ? pose : trajectory.at(t); }
  // True when the pose depends on time.
  bool is_moving() const { return !trajectory.empty(); }
};

// Whether two shapes are the same solid (kind, size and mesh).
inline bool same_shape(const Shape& a, const Shape& b) {
  return a.kind == b.kind && a.size == b.size && a.mesh_path == b.mesh_path &&
         a.mesh_scale == b.mesh_scale;
}

// Whether two fixed obstacles are the same solid at the same pose (ids not compared); false
// when either moves.
inline bool same_static_obstacle(const Obstacle& a, const Obstacle& b) {
  return !a.is_moving() && !b.is_moving() && same_shape(a.shape, b.shape) &&
         a.pose.matrix() == b.pose.matrix();
}

}  // namespace kinograph::collision

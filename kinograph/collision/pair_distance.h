#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>

#include "kinograph/collision/convex_shape.h"

namespace kinograph::collision {

// Signed distance between two convex solids A and B with its witness points.
struct PairDistance {
  // False when the distance exceeds the caller's max_distance, or (rarely) when GJK/EPA
  // reported no result for degenerate input; the other fields are then unset.
  bool valid = false;
  // Euclidean distance when separated, minus the penetration depth when overlapping.
  double distance = 0;
  // Witness point on A's surface (world frame).
  Eigen::Vector3d point_on_a = Eigen::Vector3d::Zero();
  // Witness point on B's surface (world frame).
  Eigen::Vector3d point_on_b = Eigen::Vector3d::Zero();
  // Unit normal pointing from B towards A: moving A along it increases the distance.
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
};

// Exact signed distance between A at pose a_to_world and B at pose b_to_world, by Bullet's
// btGjkPairDetector (GJK when separated, GJK-EPA when penetrating) with a Voronoi simplex
// solver. With a finite max_distance, GJK stops as soon as its lower bound passes it and the
// result is invalid: only pairs closer than max_distance are reported. Allocates nothing; the
// solvers live on the stack.
PairDistance pair_distance(const ConvexShape& a, const Eigen::Isometry3d& a_to_world,
                           const ConvexShape& b, const Eigen::Isometry3d& b_to_world,
                           double max_distance = std::numeric_limits<double>::infinity());

}  // namespace kinograph::collision

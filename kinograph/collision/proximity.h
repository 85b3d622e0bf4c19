#pragma once

#include <Eigen/Core>

namespace kinograph::collision {

// The signed distance between one robot collision geometry and one obstacle (or, for
// self-collision, a second robot geometry), with world witness points and normal.
struct Proximity {
  int robot_geom = -1;  // index into dynamics::Model::collision
  int obstacle = -1;    // obstacle id; -1 for a self-collision pair
  int other_geom = -1;  // self-collision pairs: the second geometry; -1 otherwise
  // Signed distance (m): > 0 separated, < 0 penetrating by that depth.
  double distance = 0;
  Eigen::Vector3d point_on_robot = Eigen::Vector3d::Zero();     // on robot_geom, world
  Eigen::Vector3d point_on_obstacle = Eigen::Vector3d::Zero();  // on the obstacle/other_geom
  // Unit normal from the obstacle (or other_geom) towards the robot geometry: moving the
  // robot's witness point along it increases the distance.
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();

  // True for a pair of two robot geometries (other_geom set, obstacle -1).
  bool is_self_collision() const { return other_geom >= 0; }
};

}  // namespace kinograph::collision

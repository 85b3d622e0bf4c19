#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "kinograph/collision/convex_shape.h"
#include "kinograph/collision/obstacle.h"
#include "kinograph/collision/proximity.h"
#include "kinograph/collision/status.h"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/model.h"

namespace kinograph::collision {

// How a CollisionWorld chooses the pairs it reports.
struct CollisionWorldOptions {
  // Pairs whose signed distance exceeds this (m) are not reported by query(); the planner's
  // hinge ignores them anyway. Default 0.3 m, a few times a typical safety distance.
  double query_distance = 0.3;
  // Cull pairs by bounding spheres before running GJK. Only a speed-up: turning it off must
  // not change any result (tests compare both). Default on.
  bool cull = true;
  // Also report pairs of robot geometries on bodies that are neither the same nor parent and
  // child. Default off: arm links rarely meet, and the check costs O(n²).
  bool self_collision = false;
  // Body pairs (indices into Model::bodies, -1 = base) never checked for self-collision, in
  // addition to adjacent ones; for links whose geometry overlaps by design.
  std::vector<std::pair<int, int>> self_collision_excluded;
  // Include geometry fixed to the base (body -1) in robot-versus-obstacle pairs. Default off:
  // the base cannot move, so such a distance has no gradient and belongs to scene checks.
  bool base_vs_obstacles = false;
};

// The collision scene of one robot: its collision geometry (from the Model, Bullet shapes made
// once) and the obstacles around it, added, moved and removed by id. Queries read the body
// poses of a Data after dynamics::forward_kinematics and allocate nothing after warm-up
// (the output buffer is sized when obstacles are added). Queries write the world's pose caches
// and output buffer, so a world belongs to one thread at a time.
class CollisionWorld {
 public:
  // Builds a Bullet shape per Model::collision entry; throws std::invalid_argument for a bad
  // geometry (the message names its URDF link). The Model must outlive the world.
  explicit CollisionWorld(const dynamics::Model& model, CollisionWorldOptions options = {});

  // Adds an obstacle; fails if the id is taken. Throws std::invalid_argument for a bad shape.
  Status add_obstacle(const Obstacle& obstacle);
  // Sets a fixed world pose (dropping any trajectory); fails for an unknown id.
  Status move_obstacle(int id, const Eigen::Isometry3d& pose);
  // Makes the obstacle move along a trajectory (an empty one keeps its last fixed pose).
  Status set_obstacle_trajectory(int id, PoseTrajectory trajectory);
  // Removes an obstacle; fails for an unknown id. Other ids are unaffected.
  Status remove_obstacle(int id);
  // Removes every obstacle.
  void clear_obstacles();
  // The obstacle with this id, or nullptr.
  const Obstacle* find_obstacle(int id) const;
  // Number of obstacles.
  int num_obstacles() const { return static_cast<int>(obstacles_.size()); }
  // True when some obstacle follows a trajectory.
  bool has_moving_obstacles() const { return moving_ > 0; }
  // The robot's collision geometry as Bullet shapes, one per Model::collision entry.
  const ConvexShape& robot_shape(int geom) const { return robot_[geom].shape; }
  // The options the world was built with.
  const CollisionWorldOptions& options() const { return options_; }
  // The robot whose geometry this world holds.
  const dynamics::Model& model() const { return model_; }
  // The self-collision pairs checked (robot geometry indices a < b); empty unless enabled.
  const std::vector<std::pair<int, int>>& self_pairs() const { return self_pairs_; }

  // Every pair within options().query_distance at the robot configuration of the last
  // forward_kinematics on `data` and obstacle poses at time t. The span stays valid until the
  // next call on this world.
  std::span<const Proximity> query(const dynamics::Data& data, double t = 0);
  // As query(data, t) with another query distance.
  std::span<const Proximity> query(const dynamics::Data& data, double t, double query_distance);
  // The pair with the smallest signed distance (over obstacles, and over self pairs when
  // enabled), culled against the best so far; distance +inf and robot_geom -1 when there is
  // nothing to check.
  Proximity closest(const dynamics::Data& data, double t = 0);

 private:
  struct RobotGeom {
    int body = -1;
    Eigen::Isometry3d origin;  // in its body's frame
    ConvexShape shape;
    Eigen::Vector3d local_centre;  // bounding sphere centre in the body's frame
    Eigen::Isometry3d world;       // valid when posed == pose_stamp_
    Eigen::Vector3d centre;        // bounding sphere centre, world (after update_poses)
    uint64_t posed = 0;
  };
  // A pair closest() may check, with its lower bound; checked in order of the bound.
  struct Candidate {
    double bound;
    int order;  // position in the brute-force visiting order (ties keep the earlier pair)
    int a, b;   // robot geometry and obstacle index, or two robot geometries (b < 0: ~b)
  };
  struct ObstacleEntry {
    Obstacle obstacle;
    ConvexShape shape;
    Eigen::Isometry3d world;
    Eigen::Vector3d centre;  // bounding sphere centre, world
    Eigen::Vector3d lo, hi;  // world AABB
    void place(const Eigen::Isometry3d& pose);
  };

  // Sets the bounding-sphere centres and moving obstacles; full geometry poses are made only
  // for pairs that survive culling (geom_world).
  void update_poses(const dynamics::Data& data, double t);
  const Eigen::Isometry3d& geom_world(int g);
  void reserve_output();
  // True when the bounds prove the pair's signed distance exceeds `threshold` (no square roots
  // when threshold + radii >= 0).
  bool beyond(int g, const ObstacleEntry& o, double threshold) const;
  bool beyond(int a, int b, double threshold) const;
  // After any change of the obstacles: recounts the moving ones.
  void obstacles_changed();
  int find_index(int id) const;
  // Fills `out` with the pair's signed distance if it is at most max_distance.
  bool robot_obstacle(int g, const ObstacleEntry& o, double max_distance, Proximity& out);
  bool robot_robot(int a, int b, double max_distance, Proximity& out);
  // A lower bound of the pair's signed distance from bounding spheres and boxes.
  double lower_bound(int g, const ObstacleEntry& o) const;
  double lower_bound(int a, int b) const;
  // Robot geometry indices that take part in obstacle pairs.
  bool checks_obstacles(int g) const { return options_.base_vs_obstacles || robot_[g].body >= 0; }

  const dynamics::Model& model_;
  CollisionWorldOptions options_;
  std::vector<RobotGeom> robot_;
  std::vector<std::pair<int, int>> self_pairs_;  // robot geometry index pairs
  std::vector<ObstacleEntry> obstacles_;
  int moving_ = 0;  // obstacles with a trajectory
  std::vector<Proximity> out_;
  std::vector<Candidate> candidates_;
  uint64_t pose_stamp_ = 0;
  const dynamics::Data* data_ = nullptr;  // of the current query, for geom_world
};

}  // namespace kinograph::collision

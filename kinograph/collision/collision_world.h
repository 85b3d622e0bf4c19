#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "kinograph/collision/capsule_bound.h"
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
  // Cull pairs by bounds before running GJK (per link a capsule, per geometry a sphere and a
  // capsule). Only a speed-up: turning it off must not change any result (tests compare both).
  // Default on.
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
  // True when some pair is within `distance` (what query(data, t, distance) would report),
  // stopping at the first one found.
  bool any_within(const dynamics::Data& data, double t, double distance);
  // The pair with the smallest signed distance (over obstacles, and over self pairs when
  // enabled), culled against the best so far; distance +inf and robot_geom -1 when there is
  // nothing to check.
  Proximity closest(const dynamics::Data& data, double t = 0);
  // A pair closest() considers: robot geometry `a` against obstacle index `b`, or (self) robot
  // geometries a and b.
  struct PairIndex {
    int a = 0, b = 0;
    bool self = false;
  };
  // The pairs closest() considers, in the order of pair_bounds(): every robot geometry that
  // checks obstacles against each obstacle, then the self pairs. Fills `out` (reusing it).
  void closest_pairs(std::vector<PairIndex>& out) const;
  // After closest(): per pair of closest_pairs(), a lower bound of its signed distance (the
  // distance itself where closest() measured it; culled pairs keep the bound that culled them).
  // Valid until the next query on this world.
  std::span<const double> pair_bounds() const { return pair_bounds_; }

 private:
  struct RobotGeom {
    int body = -1;
    Eigen::Isometry3d origin;  // in its body's frame
    ConvexShape shape;
    Eigen::Vector3d local_centre;  // bounding sphere centre in the body's frame
    CapsuleBound local_capsule;    // bounding capsule in the body's frame
    Eigen::Isometry3d world;       // valid when posed == pose_stamp_
    Eigen::Vector3d centre;        // bounding sphere centre, world; valid when centred == stamp
    CapsuleBound capsule;          // bounding capsule, world; valid when capsuled == stamp
    uint64_t posed = 0, centred = 0, capsuled = 0;
    bool elongated = false;  // the capsule is longer than a point (else it is the sphere)
  };
  // A capsule around all geometry of one body (index body + 1; the base is 0), posed per query.
  struct BodyBound {
    CapsuleBound local, world;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // of the sphere around it, world
    double sphere_radius = 0;
    bool present = false;  // the body has collision geometry
  };
  // A pair closest() may check, with its lower bound; checked in order of the bound.
  struct Candidate {
    double bound;
    int order;  // position in the brute-force visiting order (ties keep the earlier pair)
    int a, b;   // robot geometry and obstacle index, or (b < 0) the index of a self pair
  };
  struct ObstacleEntry {
    Obstacle obstacle;
    ConvexShape shape;
    Eigen::Isometry3d world;
    Eigen::Vector3d centre;  // bounding sphere centre, world
    Eigen::Vector3d lo, hi;  // world AABB
    void place(const Eigen::Isometry3d& pose);
  };

  // Poses the body capsules and moving obstacles; link-level bounds, geometry bounds and poses
  // are made only for pairs that reach them (body_bound, centre, capsule, geom_world).
  void update_poses(const dynamics::Data& data, double t);
  // Fills out_ with the pairs within query_distance, in order; only the first with first_only.
  void scan(const dynamics::Data& data, double t, double query_distance, bool first_only);
  const Eigen::Isometry3d& geom_world(int g);
  const Eigen::Vector3d& centre(int g);
  const CapsuleBound& capsule(int g);
  void reserve_output();
  // True when the geometry bounds prove the pair's signed distance exceeds `threshold`: the
  // sphere (no square roots when threshold + radii >= 0), then the capsule.
  bool beyond(int g, int o, double threshold);
  bool beyond_self(int pair, double threshold);
  // After any change of the obstacles: recounts the moving ones and resizes the link bounds.
  void obstacles_changed();
  int find_index(int id) const;
  // Fills `out` with the pair's signed distance if it is at most max_distance.
  bool robot_obstacle(int g, const ObstacleEntry& o, double max_distance, Proximity& out);
  bool robot_robot(int a, int b, double max_distance, Proximity& out);
  // Lower bounds of the pair's signed distance: from the link bound and the geometry's bounding
  // sphere (and box), and the tighter one that adds the geometry's capsule.
  double lower_bound(int g, int o);
  double lower_bound_self(int pair);
  double capsule_bound(int g, int o);
  double capsule_bound_self(int pair);
  // Link-level lower bounds, made at most once per query: body and obstacle (body capsule
  // against the obstacle's sphere and box), and the i-th self body pair.
  double body_bound(int body, int o);
  double body_pair_bound(int i);
  // Sets body_obstacle_near_ and body_pair_near_: false where the link bounds prove the pair
  // farther apart than threshold.
  void mark_near_bodies(double threshold);
  // Robot geometry indices that take part in obstacle pairs.
  bool checks_obstacles(int g) const { return options_.base_vs_obstacles || robot_[g].body >= 0; }

  const dynamics::Model& model_;
  CollisionWorldOptions options_;
  std::vector<RobotGeom> robot_;
  std::vector<std::pair<int, int>> self_pairs_;  // robot geometry index pairs
  std::vector<int> self_body_pair_;              // per self pair: its index in body_pairs_
  std::vector<std::pair<int, int>> body_pairs_;  // body indices (+1) of the self pairs
  std::vector<double> body_pair_bound_;          // per body pair: link-level lower bound
  std::vector<uint64_t> body_pair_stamp_;        // pose_stamp_ when body_pair_bound_ was made
  std::vector<char> body_pair_near_;             // per body pair: not culled by mark_near_bodies
  std::vector<BodyBound> bodies_;                // per body + 1
  std::vector<double> body_obstacle_bound_;      // [(body + 1) * obstacles + o]: lower bound
  std::vector<uint64_t> body_obstacle_stamp_;    // pose_stamp_ when it was made
  std::vector<char> body_obstacle_near_;         // [(body + 1) * obstacles + o]: not culled
  std::vector<ObstacleEntry> obstacles_;
  int moving_ = 0;  // obstacles with a trajectory
  std::vector<Proximity> out_;
  std::vector<Candidate> candidates_;
  std::vector<double> pair_bounds_;  // closest()'s lower bound per pair, by Candidate::order
  uint64_t pose_stamp_ = 0;
  const dynamics::Data* data_ = nullptr;  // of the current query, for geom_world
};

}  // namespace kinograph::collision

#include "kinograph/collision/collision_world.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "kinograph/collision/pair_distance.h"

namespace kinograph::collision {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

ConvexShape make_robot_shape(const dynamics::Geometry& g, size_t index) {
  try {
    return ConvexShape(shape_of(g));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("collision geometry " + std::to_string(index) + " of link '" +
                                g.link_name + "': " + e.what());
  }
}

bool adjacent(const dynamics::Model& model, int a, int b) {
  if (a == b) return true;
  if (a >= 0 && model.bodies[a].parent == b) return true;
  if (b >= 0 && model.bodies[b].parent == a) return true;
  return false;
}

// Distance from a point to an axis-aligned box (0 inside).
double point_box_gap(const Eigen::Vector3d& p, const Eigen::Vector3d& lo,
                     const Eigen::Vector3d& hi) {
  return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).norm();
}

}  // namespace

CollisionWorld::CollisionWorld(const dynamics::Model& model, CollisionWorldOptions options)
    : model_(model), options_(std::move(options)) {
  bullet_precision_link_guard();
  robot_.reserve(model.collision.size());
  for (size_t i = 0; i < model.collision.size(); ++i) {
    const dynamics::Geometry& g = model.collision[i];
    if (g.body < -1 || g.body >= model.nq()) {
      throw std::invalid_argument("collision geometry " + std::to_string(i) + " of link '" +
                                  g.link_name + "' names body " + std::to_string(g.body));
    }
    robot_.push_back(
        RobotGeom{g.body, g.origin, make_robot_shape(g, i), g.origin, g.origin.translation()});
  }
  if (options_.self_collision) {
    for (int a = 0; a < static_cast<int>(robot_.size()); ++a) {
      for (int b = a + 1; b < static_cast<int>(robot_.size()); ++b) {
        const int ba = robot_[a].body, bb = robot_[b].body;
        if (adjacent(model, ba, bb)) continue;
        const bool excluded = std::any_of(
            options_.self_collision_excluded.begin(), options_.self_collision_excluded.end(),
            [&](const std::pair<int, int>& e) {
              return (e.first == ba && e.second == bb) || (e.first == bb && e.second == ba);
            });
        if (!excluded) self_pairs_.emplace_back(a, b);
      }
    }
  }
  reserve_output();
  spdlog::debug("collision world: {} robot geometries, {} self-collision pairs", robot_.size(),
                self_pairs_.size());
}

void CollisionWorld::reserve_output() {
  out_.reserve(robot_.size() * obstacles_.size() + self_pairs_.size());
}

int CollisionWorld::find_index(int id) const {
  for (size_t i = 0; i < obstacles_.size(); ++i) {
    if (obstacles_[i].obstacle.id == id) return static_cast<int>(i);
  }
  return -1;
}

Status CollisionWorld::add_obstacle(const Obstacle& obstacle) {
  if (find_index(obstacle.id) >= 0) {
    return Status::failure("obstacle id " + std::to_string(obstacle.id) + " already exists");
  }
  ConvexShape shape = [&] {
    try {
      return ConvexShape(obstacle.shape);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("obstacle " + std::to_string(obstacle.id) + ": " + e.what());
    }
  }();
  ObstacleEntry entry{obstacle, std::move(shape), {}, {}, {}, {}};
  entry.place(obstacle.pose_at(0));
  obstacles_.push_back(std::move(entry));
  reserve_output();
  return Status::success();
}

Status CollisionWorld::move_obstacle(int id, const Eigen::Isometry3d& pose) {
  const int i = find_index(id);
  if (i < 0) return Status::failure("no obstacle with id " + std::to_string(id));
  ObstacleEntry& o = obstacles_[i];
  o.obstacle.pose = pose;
  o.obstacle.trajectory = PoseTrajectory();
  o.place(pose);
  return Status::success();
}

Status CollisionWorld::set_obstacle_trajectory(int id, PoseTrajectory trajectory) {
  const int i = find_index(id);
  if (i < 0) return Status::failure("no obstacle with id " + std::to_string(id));
  ObstacleEntry& o = obstacles_[i];
  o.obstacle.trajectory = std::move(trajectory);
  o.place(o.obstacle.pose_at(0));
  return Status::success();
}

Status CollisionWorld::remove_obstacle(int id) {
  const int i = find_index(id);
  if (i < 0) return Status::failure("no obstacle with id " + std::to_string(id));
  obstacles_.erase(obstacles_.begin() + i);
  return Status::success();
}

void CollisionWorld::clear_obstacles() { obstacles_.clear(); }

const Obstacle* CollisionWorld::find_obstacle(int id) const {
  const int i = find_index(id);
  return i < 0 ? nullptr : &obstacles_[i].obstacle;
}

bool CollisionWorld::has_moving_obstacles() const {
  return std::any_of(obstacles_.begin(), obstacles_.end(),
                     [](const ObstacleEntry& o) { return o.obstacle.is_moving(); });
}

void CollisionWorld::update_poses(const dynamics::Data& data, double t) {
  for (RobotGeom& g : robot_) {
    g.world = g.body < 0 ? g.origin : data.body_pose[g.body] * g.origin;
    g.centre = g.world * g.shape.bound_center();
  }
  for (ObstacleEntry& o : obstacles_) {
    if (!o.obstacle.is_moving()) continue;  // fixed poses are set on add and move
    o.place(o.obstacle.trajectory.at(t));
  }
}

void CollisionWorld::ObstacleEntry::place(const Eigen::Isometry3d& pose) {
  world = pose;
  centre = pose * shape.bound_center();
  shape.world_aabb(pose, lo, hi);
}

double CollisionWorld::lower_bound(int g, const ObstacleEntry& o) const {
  const RobotGeom& rg = robot_[g];
  const double r = rg.shape.bound_radius();
  // Both bounds hold for penetration depth too: moving the robot's bounding sphere clear of
  // the obstacle's bounding sphere (or, if its centre is outside it, of the obstacle's box)
  // separates the solids. With the centre inside the box the box says nothing.
  const double sphere_bound = (rg.centre - o.centre).norm() - r - o.shape.bound_radius();
  const double gap = point_box_gap(rg.centre, o.lo, o.hi);
  return gap > 0 ? std::max(sphere_bound, gap - r) : sphere_bound;
}

double CollisionWorld::lower_bound(int a, int b) const {
  return (robot_[a].centre - robot_[b].centre).norm() - robot_[a].shape.bound_radius() -
         robot_[b].shape.bound_radius();
}

bool CollisionWorld::robot_obstacle(int g, const ObstacleEntry& o, double max_distance,
                                    Proximity& out) const {
  const PairDistance d =
      pair_distance(robot_[g].shape, robot_[g].world, o.shape, o.world, max_distance);
  if (!d.valid) return false;
  out.robot_geom = g;
  out.obstacle = o.obstacle.id;
  out.other_geom = -1;
  out.distance = d.distance;
  out.point_on_robot = d.point_on_a;
  out.point_on_obstacle = d.point_on_b;
  out.normal = d.normal;
  return true;
}

bool CollisionWorld::robot_robot(int a, int b, double max_distance, Proximity& out) const {
  const PairDistance d = pair_distance(robot_[a].shape, robot_[a].world, robot_[b].shape,
                                       robot_[b].world, max_distance);
  if (!d.valid) return false;
  out.robot_geom = a;
  out.obstacle = -1;
  out.other_geom = b;
  out.distance = d.distance;
  out.point_on_robot = d.point_on_a;
  out.point_on_obstacle = d.point_on_b;
  out.normal = d.normal;
  return true;
}

std::span<const Proximity> CollisionWorld::query(const dynamics::Data& data, double t) {
  return query(data, t, options_.query_distance);
}

std::span<const Proximity> CollisionWorld::query(const dynamics::Data& data, double t,
                                                 double query_distance) {
  update_poses(data, t);
  out_.clear();
  // Without culling every pair goes through GJK to the end: the brute-force reference.
  const double gjk_max = options_.cull ? query_distance : kInfinity;
  Proximity p;
  for (int g = 0; g < static_cast<int>(robot_.size()); ++g) {
    if (!checks_obstacles(g)) continue;
    for (const ObstacleEntry& o : obstacles_) {
      if (options_.cull && lower_bound(g, o) > query_distance) continue;
      if (robot_obstacle(g, o, gjk_max, p) && p.distance <= query_distance) out_.push_back(p);
    }
  }
  for (const auto& [a, b] : self_pairs_) {
    if (options_.cull && lower_bound(a, b) > query_distance) continue;
    if (robot_robot(a, b, gjk_max, p) && p.distance <= query_distance) out_.push_back(p);
  }
  return {out_.data(), out_.size()};
}

Proximity CollisionWorld::closest(const dynamics::Data& data, double t) {
  update_poses(data, t);
  Proximity best;
  best.distance = kInfinity;
  Proximity p;
  // Each pair only needs checking to the best distance so far.
  for (int g = 0; g < static_cast<int>(robot_.size()); ++g) {
    if (!checks_obstacles(g)) continue;
    for (const ObstacleEntry& o : obstacles_) {
      if (options_.cull && lower_bound(g, o) >= best.distance) continue;
      const double gjk_max = options_.cull ? best.distance : kInfinity;
      if (robot_obstacle(g, o, gjk_max, p) && p.distance < best.distance) best = p;
    }
  }
  for (const auto& [a, b] : self_pairs_) {
    if (options_.cull && lower_bound(a, b) >= best.distance) continue;
    const double gjk_max = options_.cull ? best.distance : kInfinity;
    if (robot_robot(a, b, gjk_max, p) && p.distance < best.distance) best = p;
  }
  return best;
}

}  // namespace kinograph::collision

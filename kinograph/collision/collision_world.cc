#include "kinograph/collision/collision_world.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "kinograph/collision/pair_distance.h"

namespace kinograph::collision {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Culling keeps pairs whose lower bound is within this of the threshold, so a bound that rounds
// a hair above an exact distance (sphere against sphere or box face) cannot drop a pair at the
// cut-off. GJK decides those pairs.
constexpr double kCullSlack = 1e-9;

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
    ConvexShape shape = make_robot_shape(g, i);
    const Eigen::Vector3d local_centre = g.origin * shape.bound_center();
    robot_.push_back(
        RobotGeom{g.body, g.origin, std::move(shape), local_centre, g.origin, local_centre, 0});
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
  const size_t max_results = robot_.size() * obstacles_.size() + self_pairs_.size();
  out_.reserve(max_results);
  candidates_.reserve(max_results);
}

void CollisionWorld::obstacles_changed() {
  moving_ = static_cast<int>(
      std::count_if(obstacles_.begin(), obstacles_.end(),
                    [](const ObstacleEntry& o) { return o.obstacle.is_moving(); }));
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
  obstacles_changed();
  return Status::success();
}

Status CollisionWorld::move_obstacle(int id, const Eigen::Isometry3d& pose) {
  const int i = find_index(id);
  if (i < 0) return Status::failure("no obstacle with id " + std::to_string(id));
  ObstacleEntry& o = obstacles_[i];
  o.obstacle.pose = pose;
  o.obstacle.trajectory = PoseTrajectory();
  o.place(pose);
  obstacles_changed();
  return Status::success();
}

Status CollisionWorld::set_obstacle_trajectory(int id, PoseTrajectory trajectory) {
  const int i = find_index(id);
  if (i < 0) return Status::failure("no obstacle with id " + std::to_string(id));
  ObstacleEntry& o = obstacles_[i];
  o.obstacle.trajectory = std::move(trajectory);
  o.place(o.obstacle.pose_at(0));
  obstacles_changed();
  return Status::success();
}

Status CollisionWorld::remove_obstacle(int id) {
  const int i = find_index(id);
  if (i < 0) return Status::failure("no obstacle with id " + std::to_string(id));
  obstacles_.erase(obstacles_.begin() + i);
  obstacles_changed();
  return Status::success();
}

void CollisionWorld::clear_obstacles() {
  obstacles_.clear();
  obstacles_changed();
}

const Obstacle* CollisionWorld::find_obstacle(int id) const {
  const int i = find_index(id);
  return i < 0 ? nullptr : &obstacles_[i].obstacle;
}

void CollisionWorld::update_poses(const dynamics::Data& data, double t) {
  ++pose_stamp_;
  for (RobotGeom& g : robot_) {
    if (g.body >= 0) g.centre = data.body_pose[g.body] * g.local_centre;
  }
  data_ = &data;
  if (moving_ == 0) return;
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

const Eigen::Isometry3d& CollisionWorld::geom_world(int g) {
  RobotGeom& rg = robot_[g];
  if (rg.body >= 0 && rg.posed != pose_stamp_) {
    rg.world = data_->body_pose[rg.body] * rg.origin;
    rg.posed = pose_stamp_;
  }
  return rg.world;
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

bool CollisionWorld::beyond(int g, const ObstacleEntry& o, double threshold) const {
  // lower_bound(g, o) > threshold, compared in squares where both sides are non-negative.
  const RobotGeom& rg = robot_[g];
  const double r = rg.shape.bound_radius();
  const double a = threshold + r + o.shape.bound_radius();
  const Eigen::Vector3d dc = rg.centre - o.centre;
  if (a >= 0 ? dc.squaredNorm() > a * a : dc.norm() > a) return true;
  const double gap2 = (o.lo - rg.centre).cwiseMax(rg.centre - o.hi).cwiseMax(0.0).squaredNorm();
  if (!(gap2 > 0)) return false;
  const double b = threshold + r;
  return b >= 0 ? gap2 > b * b : std::sqrt(gap2) > b;
}

bool CollisionWorld::beyond(int a, int b, double threshold) const {
  const double s = threshold + robot_[a].shape.bound_radius() + robot_[b].shape.bound_radius();
  const Eigen::Vector3d dc = robot_[a].centre - robot_[b].centre;
  return s >= 0 ? dc.squaredNorm() > s * s : dc.norm() > s;
}

bool CollisionWorld::robot_obstacle(int g, const ObstacleEntry& o, double max_distance,
                                    Proximity& out) {
  const PairDistance d =
      pair_distance(robot_[g].shape, geom_world(g), o.shape, o.world, max_distance);
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

bool CollisionWorld::robot_robot(int a, int b, double max_distance, Proximity& out) {
  const PairDistance d =
      pair_distance(robot_[a].shape, geom_world(a), robot_[b].shape, geom_world(b), max_distance);
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
  // Without culling every pair goes through GJK to the end: the brute-force reference. GJK's
  // early exit gets the slack too: its core-distance bound can round past a pair's distance
  // exactly at the cut-off. The cut-off itself is exact (distance <= query_distance).
  const double cull_at = query_distance + kCullSlack;
  const double gjk_max = options_.cull ? cull_at : kInfinity;
  Proximity p;
  for (int g = 0; g < static_cast<int>(robot_.size()); ++g) {
    if (!checks_obstacles(g)) continue;
    for (const ObstacleEntry& o : obstacles_) {
      if (options_.cull && beyond(g, o, cull_at)) continue;
      if (robot_obstacle(g, o, gjk_max, p) && p.distance <= query_distance) out_.push_back(p);
    }
  }
  for (const auto& [a, b] : self_pairs_) {
    if (options_.cull && beyond(a, b, cull_at)) continue;
    if (robot_robot(a, b, gjk_max, p) && p.distance <= query_distance) out_.push_back(p);
  }
  return {out_.data(), out_.size()};
}

Proximity CollisionWorld::closest(const dynamics::Data& data, double t) {
  update_poses(data, t);
  Proximity best;
  best.distance = kInfinity;
  Proximity p;
  if (!options_.cull) {  // the brute-force reference: every pair to the end, in order
    for (int g = 0; g < static_cast<int>(robot_.size()); ++g) {
      if (!checks_obstacles(g)) continue;
      for (const ObstacleEntry& o : obstacles_) {
        if (robot_obstacle(g, o, kInfinity, p) && p.distance < best.distance) best = p;
      }
    }
    for (const auto& [a, b] : self_pairs_) {
      if (robot_robot(a, b, kInfinity, p) && p.distance < best.distance) best = p;
    }
    return best;
  }
  // Pairs in order of their lower bounds, each checked only up to the best distance so far
  // (plus the slack, so that a tie still reports and the earlier pair of equals wins, as in the
  // brute-force order): usually the first pair settles it and the rest are culled unchecked.
  candidates_.clear();
  int order = 0;
  for (int g = 0; g < static_cast<int>(robot_.size()); ++g) {
    if (!checks_obstacles(g)) continue;
    for (int o = 0; o < static_cast<int>(obstacles_.size()); ++o) {
      candidates_.push_back(Candidate{lower_bound(g, obstacles_[o]), order++, g, o});
    }
  }
  for (const auto& [a, b] : self_pairs_) {
    candidates_.push_back(Candidate{lower_bound(a, b), order++, a, ~b});
  }
  if (candidates_.empty()) return best;
  int best_order = order;
  auto check = [&](const Candidate& c) {
    const double max = best.distance + kCullSlack;
    const bool valid =
        c.b >= 0 ? robot_obstacle(c.a, obstacles_[c.b], max, p) : robot_robot(c.a, ~c.b, max, p);
    if (valid &&
        (p.distance < best.distance || (p.distance == best.distance && c.order < best_order))) {
      best = p;
      best_order = c.order;
    }
  };
  auto first =
      std::min_element(candidates_.begin(), candidates_.end(),
                       [](const Candidate& x, const Candidate& y) { return x.bound < y.bound; });
  const Candidate head = *first;
  check(head);
  // Only pairs whose bound does not exceed the best distance can beat it or tie.
  auto keep_end = std::remove_if(candidates_.begin(), candidates_.end(), [&](const Candidate& c) {
    return c.order == head.order || c.bound > best.distance + kCullSlack;
  });
  std::sort(candidates_.begin(), keep_end, [](const Candidate& x, const Candidate& y) {
    return x.bound < y.bound || (x.bound == y.bound && x.order < y.order);
  });
  for (auto it = candidates_.begin(); it != keep_end; ++it) {
    if (it->bound > best.distance + kCullSlack) break;
    check(*it);
  }
  return best;
}

}  // namespace kinograph::collision

#include "kinograph/collision/collision_world.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "kinograph/collision/pair_distance.h"
#include "kinograph/graph/cancellation.h"

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
    const CapsuleBound local_capsule = transformed(g.origin, collision::capsule_bound(shape));
    robot_.push_back(RobotGeom{g.body, g.origin, std::move(shape), local_centre, local_capsule,
                               g.origin, local_centre, local_capsule, 0, 0, 0});
  }
  bodies_.resize(model.nq() + 1);
  for (int b = -1; b < model.nq(); ++b) {
    std::vector<CapsuleBound> parts;
    for (const RobotGeom& g : robot_) {
      if (g.body == b) parts.push_back(g.local_capsule);
    }
    BodyBound& bb = bodies_[b + 1];
    bb.present = !parts.empty();
    bb.local = bb.world = enclosing(parts);
    bb.centre = 0.5 * (bb.local.a + bb.local.b);
    bb.sphere_radius = 0.5 * (bb.local.b - bb.local.a).norm() + bb.local.radius;
  }
  for (RobotGeom& g : robot_) g.elongated = g.local_capsule.a != g.local_capsule.b;
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
        if (excluded) continue;
        self_pairs_.emplace_back(a, b);
        const std::pair<int, int> bp(ba + 1, bb + 1);
        const auto it = std::find(body_pairs_.begin(), body_pairs_.end(), bp);
        self_body_pair_.push_back(static_cast<int>(it - body_pairs_.begin()));
        if (it == body_pairs_.end()) body_pairs_.push_back(bp);
      }
    }
  }
  body_pair_bound_.assign(body_pairs_.size(), 0.0);
  body_pair_stamp_.assign(body_pairs_.size(), 0);
  body_pair_near_.assign(body_pairs_.size(), 1);
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
  body_obstacle_bound_.assign(bodies_.size() * obstacles_.size(), 0.0);
  body_obstacle_stamp_.assign(bodies_.size() * obstacles_.size(), 0);
  body_obstacle_near_.assign(bodies_.size() * obstacles_.size(), 1);
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
  data_ = &data;
  for (int b = 0; b < model_.nq(); ++b) {
    BodyBound& bb = bodies_[b + 1];
    if (bb.present) {
      bb.world = transformed(data.body_pose[b], bb.local);
      bb.centre = 0.5 * (bb.world.a + bb.world.b);
    }
  }
  if (moving_ > 0) {
    for (ObstacleEntry& o : obstacles_) {
      if (!o.obstacle.is_moving()) continue;  // fixed poses are set on add and move
      o.place(o.obstacle.trajectory.at(t));
    }
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

const Eigen::Vector3d& CollisionWorld::centre(int g) {
  RobotGeom& rg = robot_[g];
  if (rg.body >= 0 && rg.centred != pose_stamp_) {
    rg.centre = data_->body_pose[rg.body] * rg.local_centre;
    rg.centred = pose_stamp_;
  }
  return rg.centre;
}

const CapsuleBound& CollisionWorld::capsule(int g) {
  RobotGeom& rg = robot_[g];
  if (rg.body >= 0 && rg.capsuled != pose_stamp_) {
    rg.capsule = transformed(data_->body_pose[rg.body], rg.local_capsule);
    rg.capsuled = pose_stamp_;
  }
  return rg.capsule;
}

double CollisionWorld::body_bound(int body, int o) {
  const size_t i = (body + 1) * obstacles_.size() + o;
  if (body_obstacle_stamp_[i] != pose_stamp_) {
    const CapsuleBound& c = bodies_[body + 1].world;
    const ObstacleEntry& e = obstacles_[o];
    body_obstacle_bound_[i] = std::max(collision::lower_bound(c, e.centre, e.shape.bound_radius()),
                                       collision::lower_bound(c, e.lo, e.hi));
    body_obstacle_stamp_[i] = pose_stamp_;
  }
  return body_obstacle_bound_[i];
}

double CollisionWorld::body_pair_bound(int i) {
  if (body_pair_stamp_[i] != pose_stamp_) {
    body_pair_bound_[i] = collision::lower_bound(bodies_[body_pairs_[i].first].world,
                                                 bodies_[body_pairs_[i].second].world);
    body_pair_stamp_[i] = pose_stamp_;
  }
  return body_pair_bound_[i];
}

void CollisionWorld::mark_near_bodies(double threshold) {
  // Cheap tests first (spheres around the body capsules, the boxes around them), the capsule
  // distances only where those cannot decide.
  const size_t n = obstacles_.size();
  for (size_t b = 0; b < bodies_.size(); ++b) {
    const BodyBound& x = bodies_[b];
    if (!x.present) continue;
    const double reach = threshold + x.world.radius;
    const Eigen::Vector3d lo = x.world.a.cwiseMin(x.world.b).array() - reach;
    const Eigen::Vector3d hi = x.world.a.cwiseMax(x.world.b).array() + reach;
    for (size_t o = 0; o < n; ++o) {
      const ObstacleEntry& e = obstacles_[o];
      const bool apart = (lo.array() > e.hi.array()).any() || (hi.array() < e.lo.array()).any();
      body_obstacle_near_[b * n + o] =
          !apart && !(body_bound(static_cast<int>(b) - 1, static_cast<int>(o)) > threshold);
    }
  }
  for (size_t i = 0; i < body_pairs_.size(); ++i) {
    const BodyBound& x = bodies_[body_pairs_[i].first];
    const BodyBound& y = bodies_[body_pairs_[i].second];
    const double s = threshold + x.sphere_radius + y.sphere_radius;
    const bool apart = s >= 0 && (x.centre - y.centre).squaredNorm() > s * s;
    body_pair_near_[i] = !apart && !(body_pair_bound(static_cast<int>(i)) > threshold);
  }
}

double CollisionWorld::lower_bound(int g, int o) {
  const RobotGeom& rg = robot_[g];
  const ObstacleEntry& e = obstacles_[o];
  const Eigen::Vector3d& c = centre(g);
  const double r = rg.shape.bound_radius();
  // Both bounds hold for penetration depth too: moving the robot's bounding sphere clear of
  // the obstacle's bounding sphere (or, if its centre is outside it, of the obstacle's box)
  // separates the solids. With the centre inside the box the box says nothing.
  const double sphere_bound = (c - e.centre).norm() - r - e.shape.bound_radius();
  const double gap = point_box_gap(c, e.lo, e.hi);
  const double body = body_bound(rg.body, o);
  return std::max(body, gap > 0 ? std::max(sphere_bound, gap - r) : sphere_bound);
}

double CollisionWorld::lower_bound_self(int pair) {
  const auto [a, b] = self_pairs_[pair];
  return std::max(body_pair_bound(self_body_pair_[pair]), (centre(a) - centre(b)).norm() -
                                                              robot_[a].shape.bound_radius() -
                                                              robot_[b].shape.bound_radius());
}

double CollisionWorld::capsule_bound(int g, int o) {
  const CapsuleBound& c = capsule(g);
  const ObstacleEntry& e = obstacles_[o];
  // Against a box the sphere of a capsule-shaped obstacle rarely helps; the box does.
  const double box = collision::lower_bound(c, e.lo, e.hi);
  if (e.shape.shape().kind != ShapeKind::kSphere) return box;
  return std::max(box, collision::lower_bound(c, e.centre, e.shape.bound_radius()));
}

double CollisionWorld::capsule_bound_self(int pair) {
  return collision::lower_bound(capsule(self_pairs_[pair].first),
                                capsule(self_pairs_[pair].second));
}

bool CollisionWorld::beyond(int g, int o, double threshold) {
  const RobotGeom& rg = robot_[g];
  // The sphere and box bounds of lower_bound(g, o) > threshold, compared in squares where both
  // sides are non-negative.
  const ObstacleEntry& e = obstacles_[o];
  const Eigen::Vector3d& c = centre(g);
  const double r = rg.shape.bound_radius();
  const double a = threshold + r + e.shape.bound_radius();
  const Eigen::Vector3d dc = c - e.centre;
  if (a >= 0 ? dc.squaredNorm() > a * a : dc.norm() > a) return true;
  const double gap2 = (e.lo - c).cwiseMax(c - e.hi).cwiseMax(0.0).squaredNorm();
  const double b = threshold + r;
  if (gap2 > 0 && (b >= 0 ? gap2 > b * b : std::sqrt(gap2) > b)) return true;
  return rg.elongated && capsule_bound(g, o) > threshold;
}

bool CollisionWorld::beyond_self(int pair, double threshold) {
  const auto [a, b] = self_pairs_[pair];
  const double s = threshold + robot_[a].shape.bound_radius() + robot_[b].shape.bound_radius();
  const Eigen::Vector3d dc = centre(a) - centre(b);
  if (s >= 0 ? dc.squaredNorm() > s * s : dc.norm() > s) return true;
  return (robot_[a].elongated || robot_[b].elongated) && capsule_bound_self(pair) > threshold;
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
  scan(data, t, query_distance, false);
  return {out_.data(), out_.size()};
}

bool CollisionWorld::any_within(const dynamics::Data& data, double t, double distance) {
  // The path search asks this thousands of times: a cancelled plan stops here, world unchanged.
  graph::throw_if_cancelled();
  scan(data, t, distance, true);
  return !out_.empty();
}

void CollisionWorld::scan(const dynamics::Data& data, double t, double query_distance,
                          bool first_only) {
  update_poses(data, t);
  out_.clear();
  // Without culling every pair goes through GJK to the end: the brute-force reference. GJK's
  // early exit gets the slack too: its core-distance bound can round past a pair's distance
  // exactly at the cut-off. The cut-off itself is exact (distance <= query_distance).
  const double cull_at = query_distance + kCullSlack;
  const double gjk_max = options_.cull ? cull_at : kInfinity;
  if (options_.cull) mark_near_bodies(cull_at);
  Proximity p;
  const int n = static_cast<int>(obstacles_.size());
  for (int g = 0; g < static_cast<int>(robot_.size()); ++g) {
    if (!checks_obstacles(g)) continue;
    const char* near = body_obstacle_near_.data() + (robot_[g].body + 1) * n;
    for (int o = 0; o < n; ++o) {
      if (options_.cull && (!near[o] || beyond(g, o, cull_at))) continue;
      if (robot_obstacle(g, obstacles_[o], gjk_max, p) && p.distance <= query_distance) {
        out_.push_back(p);
        if (first_only) return;
      }
    }
  }
  for (int i = 0; i < static_cast<int>(self_pairs_.size()); ++i) {
    if (options_.cull && (!body_pair_near_[self_body_pair_[i]] || beyond_self(i, cull_at))) {
      continue;
    }
    const auto [a, b] = self_pairs_[i];
    if (robot_robot(a, b, gjk_max, p) && p.distance <= query_distance) {
      out_.push_back(p);
      if (first_only) return;
    }
  }
}

void CollisionWorld::closest_pairs(std::vector<PairIndex>& out) const {
  out.clear();
  for (int g = 0; g < static_cast<int>(robot_.size()); ++g) {
    if (!checks_obstacles(g)) continue;
    for (int o = 0; o < static_cast<int>(obstacles_.size()); ++o) out.push_back({g, o, false});
  }
  for (const auto& [a, b] : self_pairs_) out.push_back({a, b, true});
}

Proximity CollisionWorld::closest(const dynamics::Data& data, double t) {
  update_poses(data, t);
  Proximity best;
  best.distance = kInfinity;
  Proximity p;
  pair_bounds_.clear();
  if (!options_.cull) {  // the brute-force reference: every pair to the end, in order
    // A pair GJK gives no distance for keeps no bound (−inf), as it is no candidate for best.
    auto measured = [&](bool valid) {
      pair_bounds_.push_back(valid ? p.distance : -kInfinity);
      if (valid && p.distance < best.distance) best = p;
    };
    for (int g = 0; g < static_cast<int>(robot_.size()); ++g) {
      if (!checks_obstacles(g)) continue;
      for (const ObstacleEntry& o : obstacles_) measured(robot_obstacle(g, o, kInfinity, p));
    }
    for (const auto& [a, b] : self_pairs_) measured(robot_robot(a, b, kInfinity, p));
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
      candidates_.push_back(Candidate{lower_bound(g, o), order++, g, o});
    }
  }
  for (int i = 0; i < static_cast<int>(self_pairs_.size()); ++i) {
    candidates_.push_back(Candidate{lower_bound_self(i), order++, i, -1});
  }
  if (candidates_.empty()) return best;
  pair_bounds_.resize(candidates_.size());
  for (const Candidate& c : candidates_) pair_bounds_[c.order] = c.bound;
  int best_order = order;
  auto check = [&](const Candidate& c) {
    const double max = best.distance + kCullSlack;
    // The capsule bound, dearer than the sorting bound, only for pairs about to go to GJK.
    if (max < kInfinity) {
      const double capsule = c.b >= 0 ? capsule_bound(c.a, c.b) : capsule_bound_self(c.a);
      pair_bounds_[c.order] = std::max(c.bound, capsule);
      if (capsule > max) return;
    }
    const bool valid = c.b >= 0
                           ? robot_obstacle(c.a, obstacles_[c.b], max, p)
                           : robot_robot(self_pairs_[c.a].first, self_pairs_[c.a].second, max, p);
    // No distance may also mean GJK gave none: then only the bounds are known.
    if (valid) pair_bounds_[c.order] = p.distance;
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

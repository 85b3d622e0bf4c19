#include "kinograph/planning/clearance_world.h"

#include <cmath>
#include <stdexcept>

#include "kinograph/collision/convex_shape.h"
#include "kinograph/collision/pair_distance.h"

namespace kinograph::planning {
namespace {

constexpr double kFloorSide = 100.0;         // m
constexpr double kFloorThickness = 1.0;      // m
constexpr double kMountingTolerance = 1e-3;  // m

}  // namespace

collision::Obstacle floor_obstacle(double height) {
  collision::Obstacle floor;
  floor.id = kFloorId;
  floor.shape = collision::Shape::box(kFloorSide, kFloorSide, kFloorThickness);
  floor.pose.translation() = Eigen::Vector3d(0, 0, height - 0.5 * kFloorThickness);
  return floor;
}

std::optional<double> mounting_floor(const dynamics::Model& model) {
  // The base's signed distance to a floor at z = 0: 0 when it rests on it.
  const collision::Obstacle floor = floor_obstacle(0.0);
  const collision::ConvexShape floor_shape(floor.shape);
  double lowest = std::numeric_limits<double>::infinity();
  for (const dynamics::Geometry& g : model.collision) {
    if (g.body >= 0) continue;
    const collision::ConvexShape shape(collision::shape_of(g));
    const collision::PairDistance d =
        collision::pair_distance(shape, g.origin, floor_shape, floor.pose);
    if (d.valid) lowest = std::min(lowest, d.distance);
  }
  if (std::abs(lowest) <= kMountingTolerance) return 0.0;
  return std::nullopt;
}

collision::CollisionWorldOptions self_pair_options(const Problem& problem) {
  collision::CollisionWorldOptions o;
  o.self_collision = problem.self_and_floor.self_collision;
  o.self_collision_excluded = problem.self_and_floor.allowed_pairs;
  return o;
}

std::unique_ptr<collision::CollisionWorld> clearance_world(const Problem& problem,
                                                           bool with_obstacles) {
  auto world =
      std::make_unique<collision::CollisionWorld>(*problem.model, self_pair_options(problem));
  const auto add = [&](const collision::Obstacle& o, const std::string& what) {
    const collision::Status s = world->add_obstacle(o);
    if (!s.ok) throw std::invalid_argument(what + ": " + s.reason);
  };
  if (with_obstacles) {
    for (const collision::Obstacle& o : problem.obstacles)
      add(o, "obstacle " + std::to_string(o.id));
  }
  if (problem.self_and_floor.floor) add(floor_obstacle(*problem.self_and_floor.floor), "the floor");
  return world;
}

bool has_clearance_checks(const Problem& problem) {
  if (!problem.model || problem.model->collision.empty()) return false;
  return !problem.obstacles.empty() || problem.self_and_floor.floor.has_value() ||
         problem.self_and_floor.self_collision;
}

std::string describe_pair(const dynamics::Model& model, const collision::Proximity& p) {
  const auto link = [&](int g) {
    return g >= 0 && g < static_cast<int>(model.collision.size())
               ? "'" + model.collision[g].link_name + "'"
               : std::string("?");
  };
  if (p.is_self_collision()) return "links " + link(p.robot_geom) + " and " + link(p.other_geom);
  if (p.obstacle == kFloorId) return "link " + link(p.robot_geom) + " and the floor";
  return "link " + link(p.robot_geom) + " and obstacle " + std::to_string(p.obstacle);
}

}  // namespace kinograph::planning

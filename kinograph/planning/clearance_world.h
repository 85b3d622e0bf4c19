#pragma once
// Everything a plan must clear, as one collision world: the problem's obstacles, its floor and
// the robot's own link pairs (minus the allowed ones), and the pairs named in the user's terms.
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "kinograph/collision/collision_world.h"
#include "kinograph/collision/obstacle.h"
#include "kinograph/collision/proximity.h"
#include "kinograph/planning/problem.h"

namespace kinograph::planning {

/// Obstacle id of the floor in clearance worlds (out of the range any scene or message uses).
inline constexpr int kFloorId = std::numeric_limits<int>::min();

/// The floor at world height `height` (m) as a solid: a slab 100 m square and 1 m thick whose
/// top face is z = height, wide enough to lie under any arm mounted near the origin.
collision::Obstacle floor_obstacle(double height);

/// The floor a robot stands on by default: z = 0 when its base (body −1) has collision geometry
/// whose lowest point is at z = 0 within 1 mm (a floor-mounted arm, URDF base frame on the
/// mounting face); none otherwise (a hanging pendulum, a robot without base geometry).
std::optional<double> mounting_floor(const dynamics::Model& model);

/// World options that report the problem's self pairs (every non-adjacent link pair except the
/// allowed ones) when self-collision is on.
collision::CollisionWorldOptions self_pair_options(const Problem& problem);

/// A world of the problem's obstacles (when `with_obstacles`), its floor (id kFloorId) and self
/// pairs. Throws std::invalid_argument naming an obstacle that cannot be added.
std::unique_ptr<collision::CollisionWorld> clearance_world(const Problem& problem,
                                                           bool with_obstacles = true);

/// True when the problem has anything to clear (obstacles, a floor or self pairs with geometry).
bool has_clearance_checks(const Problem& problem);

/// The pair of a proximity in the user's terms: "links 'a' and 'b'", "link 'a' and the floor"
/// or "link 'a' and obstacle 3".
std::string describe_pair(const dynamics::Model& model, const collision::Proximity& p);

}  // namespace kinograph::planning

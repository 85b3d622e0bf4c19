#pragma once
// The composite robot of a cell: several robots, each standing at its own base, as one Model
// whose joints are all of theirs (the centralized planner's one robot).
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "kinograph/dynamics/model.h"

namespace kinograph::dynamics {

/// One robot of a composite: its name (the prefix of its names), its model and its base pose.
struct ComposedPart {
  std::string name;
  const Model* model = nullptr;  ///< the robot at the world origin (not yet placed)
  Eigen::Isometry3d world_from_base = Eigen::Isometry3d::Identity();
};

/// Where each robot sits in a composite: its bodies (and joint coordinates) are
/// [offset, offset + nq), its geometries [collision_offset, ...) and [visual_offset, ...).
struct ComposedRange {
  std::string name;
  int offset = 0;
  int nq = 0;
  int collision_offset = 0, collision_count = 0;
  int visual_offset = 0, visual_count = 0;
};

/// The separator of a robot's name and its own link, joint and frame names ("left/iiwa_joint_1").
inline constexpr char kComposeSeparator = '/';

/// One Model of all parts, each placed at its base (place_base); bodies keep their order robot
/// by robot (so the tree stays topological), every link, joint, frame and geometry link name is
/// prefixed "<name>/", the bases' geometry and mass stay on the fixed base (body −1).
/// Throws std::invalid_argument for no parts, an empty, repeated or '/'-containing name, a null
/// model, a bad base pose, or parts whose gravity differs.
Model compose(const std::vector<ComposedPart>& parts, std::vector<ComposedRange>* ranges = nullptr);

/// The composite name of a robot's own link, joint or frame name: "<robot>/<name>".
std::string composed_name(const std::string& robot, const std::string& name);

}  // namespace kinograph::dynamics

#pragma once
// Pictures of several robots sharing a workspace: the robots as one composite model
// (dynamics::compose), each in its own colour, moving along their own plans on one clock, so
// a strip or a ghost view draws them all in every frame.
#include <Eigen/Core>
#include <vector>

#include "kinograph/dynamics/model_compose.h"
#include "render/render_scene.h"

namespace kinograph::render {

/// Robot i's colour in multi-robot pictures (a palette of 8, repeated).
Eigen::Vector4d robot_colour(int i);

/// The composite with every robot's visual shapes in its robot_colour, shaded by the URDF's own
/// colours (dark parts stay darker), so robots of one kind tell apart.
dynamics::Model colour_robots(const dynamics::Model& composite,
                              const std::vector<dynamics::ComposedRange>& ranges);

/// The robots' trajectories as one of the composite: sampled at the union of their times, each
/// robot held at its first and last pose outside its own. @throws std::invalid_argument when
/// the counts differ, a trajectory is empty or a pose does not fit its robot.
Trajectory cell_trajectory(const std::vector<Trajectory>& robots,
                           const std::vector<dynamics::ComposedRange>& ranges);

/// One path per robot for a ghost view: its `frame` (its own name, prefixed here), in its colour.
std::vector<ScenePath> robot_paths(const std::vector<dynamics::ComposedRange>& ranges,
                                   const std::vector<std::string>& frames);

}  // namespace kinograph::render

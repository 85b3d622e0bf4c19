#pragma once
// Pictures of plan files: what the planner's reader (planning/io/plan_json.h) gives, turned into
// what the renderer draws — the robot's trajectory and the obstacles with their colours.
#include <vector>

#include "kinograph/planning/plan.h"
#include "kinograph/planning/io/plan_json.h"
#include "render/render_scene.h"

namespace kinograph::render {

/// A plan file's obstacles as drawn: each with its "rgba" or the default blue, moving ones
/// with their motion.
std::vector<SceneObstacle> plan_obstacles(const planning::PlanFileInfo& info);
/// Points of the plan's interpolant drawn per interval (docs/interpolation.md); the renderer's
/// linear blend between them stays within the drawing's resolution.
inline constexpr int kDrawnSamplesPerInterval = 10;
/// A plan's joint positions over time: its interpolant sampled kDrawnSamplesPerInterval times
/// per interval. Throws std::invalid_argument when the plan does not fit the model.
Trajectory plan_trajectory(const dynamics::Model& model, const planning::Plan& plan);
/// The picture's scene of a whole plan file: its robot, trajectory and obstacles. The scene
/// borrows `file.model`, so `file` must outlive it.
RenderScene plan_scene(const planning::PlanFile& file);

}  // namespace kinograph::render

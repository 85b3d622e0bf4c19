#pragma once
// Pictures without a plan: a scene file's robot at its start among its obstacles, or a bare
// robot at rest, as one-pose scenes for the renderer (`kinograph render scene.yaml`).
#include <Eigen/Core>

#include "kinograph/dynamics/model.h"
#include "kinograph/planning/io/scene.h"
#include "render/render_scene.h"

namespace kinograph::render {

/// The scene's robot at its start configuration among its obstacles (named as in the file),
/// with the scene's camera. Borrows `scene.problem.model`, so `scene` must outlive it.
RenderScene start_scene(const planning::Scene& scene);

/// `model` alone at its rest pose (rest_pose). Borrows `model`.
RenderScene robot_scene(const dynamics::Model& model);

/// Every joint at 0, moved to the nearer limit where 0 is outside the joint's range.
Eigen::VectorXd rest_pose(const dynamics::Model& model);

}  // namespace kinograph::render

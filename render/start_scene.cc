#include "render/start_scene.h"

#include <algorithm>

#include "render/scene_camera.h"

namespace kinograph::render {
namespace {

RenderScene still(const dynamics::Model& model, const Eigen::VectorXd& q) {
  RenderScene scene;
  scene.model = &model;
  scene.trajectory.t = {0.0};
  scene.trajectory.q = {q};
  return scene;
}

}  // namespace

RenderScene start_scene(const planning::Scene& scene) {
  const planning::Problem& problem = scene.problem;
  RenderScene out = still(*problem.model, problem.start_q);
  for (std::size_t i = 0; i < problem.obstacles.size(); ++i) {
    SceneObstacle o;
    o.obstacle = problem.obstacles[i];
    if (i < scene.obstacle_names.size()) o.name = scene.obstacle_names[i];
    out.obstacles.push_back(std::move(o));
  }
  if (!scene.source.empty()) out.camera = read_scene_camera(scene.source);
  return out;
}

RenderScene robot_scene(const dynamics::Model& model) { return still(model, rest_pose(model)); }

Eigen::VectorXd rest_pose(const dynamics::Model& model) {
  Eigen::VectorXd q = Eigen::VectorXd::Zero(model.nq());
  for (int j = 0; j < model.nq(); ++j) {
    const auto& limits = model.bodies[j].limits;
    q[j] = std::clamp(0.0, limits.lower, limits.upper);
  }
  return q;
}

}  // namespace kinograph::render

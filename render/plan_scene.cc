#include "render/plan_scene.h"

namespace kinograph::render {

std::vector<SceneObstacle> plan_obstacles(const planning::PlanFileInfo& info) {
  std::vector<SceneObstacle> out;
  for (std::size_t i = 0; i < info.obstacles.size(); ++i) {
    SceneObstacle o;
    o.obstacle = info.obstacles[i];
    if (i < info.obstacle_rgba.size() && info.obstacle_rgba[i]) o.rgba = *info.obstacle_rgba[i];
    if (i < info.obstacle_names.size()) o.name = info.obstacle_names[i];
    out.push_back(std::move(o));
  }
  return out;
}

Trajectory plan_trajectory(const planning::Plan& plan) {
  Trajectory trajectory;
  trajectory.t = plan.t;
  for (Eigen::Index k = 0; k < plan.q.rows(); ++k)
    trajectory.q.push_back(plan.q.row(k).transpose());
  return trajectory;
}

RenderScene plan_scene(const planning::PlanFile& file) {
  RenderScene scene;
  scene.model = file.model.get();
  scene.trajectory = plan_trajectory(file.plan);
  scene.obstacles = plan_obstacles(file.info);
  return scene;
}

}  // namespace kinograph::render

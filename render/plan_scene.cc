#include "render/plan_scene.h"

#include <stdexcept>

#include "kinograph/planning/trajectory_sampler.h"

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

Trajectory plan_trajectory(const dynamics::Model& model, const planning::Plan& plan) {
  const planning::SampledPath path = planning::sample_plan(model, plan, kDrawnSamplesPerInterval);
  Trajectory trajectory;
  trajectory.t = path.t;
  for (Eigen::Index k = 0; k < path.q.rows(); ++k)
    trajectory.q.push_back(path.q.row(k).transpose());
  return trajectory;
}

RenderScene plan_scene(const planning::PlanFile& file) {
  RenderScene scene;
  scene.model = file.model.get();
  if (file.model == nullptr) throw std::invalid_argument("plan file: no robot model");
  scene.trajectory = plan_trajectory(*file.model, file.plan);
  scene.obstacles = plan_obstacles(file.info);
  return scene;
}

}  // namespace kinograph::render

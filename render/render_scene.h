#pragma once
// What the renderer draws: a robot model moving along a trajectory among obstacles.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "kinograph/collision/obstacle.h"
#include "kinograph/dynamics/model.h"
#include "render/camera.h"

namespace kinograph::render {

/// Joint positions sampled in time (a plan's t and q).
struct Trajectory {
  std::vector<double> t;           ///< increasing sample times, s
  std::vector<Eigen::VectorXd> q;  ///< joint positions at each time, one per sample

  /// Joint positions at `time`, linearly interpolated and clamped to the ends.
  Eigen::VectorXd at(double time) const;
  /// `count` times spread evenly from the first to the last sample (the first if count is 1).
  std::vector<double> even_times(int count) const;
};

/// An obstacle as drawn: the planner's obstacle (shape, and a fixed pose or a motion on the
/// plan's clock, so a moving one is drawn where it is at each frame's time) and its colour.
struct SceneObstacle {
  collision::Obstacle obstacle;
  /// Plans carry no colours by default: obstacles get one blue that no robot part uses.
  Eigen::Vector4d rgba = Eigen::Vector4d(0.30, 0.55, 0.85, 1.0);
  std::string name;  ///< the plan file's id, to tell obstacles of two plans apart
};

/// A frame whose path a ghost overlay draws, in its own colour.
struct ScenePath {
  std::string frame;
  Eigen::Vector4f rgba = Eigen::Vector4f(0.85f, 0.12f, 0.08f, 1.f);
};

/// Everything a picture of a plan depends on. The model is borrowed and must outlive the
/// scene.
struct RenderScene {
  const dynamics::Model* model = nullptr;
  Trajectory trajectory;
  std::vector<SceneObstacle> obstacles;
  std::optional<Camera> camera;    ///< automatic framing when absent
  std::string end_effector_frame;  ///< frame whose path a ghost overlay draws; empty = last frame
  /// Paths a ghost overlay draws instead, each in its colour (several robots in one model).
  std::vector<ScenePath> paths;

  /// Throws std::invalid_argument naming the problem when the scene cannot be drawn (no model,
  /// empty trajectory, joint vectors of the wrong size, decreasing times).
  void check() const;
};

/// Gives `rgba` to the obstacles of `after` that `before` does not have as they are (new, or
/// moved or reshaped under the same name), so a replanning figure shows what changed. Returns
/// how many it marked.
int highlight_changed_obstacles(const RenderScene& before, RenderScene& after,
                                const Eigen::Vector4d& rgba);

/// The common world direction of all joint axes when the robot is planar (every joint axis
/// parallel, checked at configuration q), else nullopt. Such robots are best seen along it.
std::optional<Eigen::Vector3d> planar_axis(const dynamics::Model& model, const Eigen::VectorXd& q);

}  // namespace kinograph::render

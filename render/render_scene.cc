#include "render/render_scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"

namespace kinograph::render {

Eigen::VectorXd Trajectory::at(double time) const {
  if (t.empty()) throw std::invalid_argument("Trajectory::at: empty trajectory");
  if (time <= t.front()) return q.front();
  if (time >= t.back()) return q.back();
  const auto upper = std::upper_bound(t.begin(), t.end(), time);
  const std::size_t i = static_cast<std::size_t>(upper - t.begin());  // t[i-1] <= time < t[i]
  const double span = t[i] - t[i - 1];
  const double s = span > 0 ? (time - t[i - 1]) / span : 0.0;
  return (1.0 - s) * q[i - 1] + s * q[i];
}

std::vector<double> Trajectory::even_times(int count) const {
  std::vector<double> times;
  if (t.empty() || count <= 0) return times;
  if (count == 1) return {t.front()};
  for (int i = 0; i < count; ++i) {
    times.push_back(t.front() + (t.back() - t.front()) * i / (count - 1));
  }
  return times;
}

void RenderScene::check() const {
  if (model == nullptr) throw std::invalid_argument("render scene: no robot model");
  if (trajectory.t.empty()) throw std::invalid_argument("render scene: empty trajectory");
  if (trajectory.q.size() != trajectory.t.size()) {
    throw std::invalid_argument(fmt::format("render scene: {} times but {} joint vectors",
                                            trajectory.t.size(), trajectory.q.size()));
  }
  for (std::size_t k = 0; k < trajectory.q.size(); ++k) {
    if (trajectory.q[k].size() != model->nq()) {
      throw std::invalid_argument(
          fmt::format("render scene: q[{}] has {} entries, the robot '{}' has {} joints", k,
                      trajectory.q[k].size(), model->name, model->nq()));
    }
    if (k > 0 && trajectory.t[k] < trajectory.t[k - 1]) {
      throw std::invalid_argument(fmt::format("render scene: t[{}] decreases", k));
    }
  }
  if (!end_effector_frame.empty()) model->frame_index(end_effector_frame);  // throws if unknown
  for (const ScenePath& path : paths) model->frame_index(path.frame);
}

int highlight_changed_obstacles(const RenderScene& before, RenderScene& after,
                                const Eigen::Vector4d& rgba) {
  int marked = 0;
  const auto same = [](const collision::Obstacle& a, const collision::Obstacle& b) {
    if (a.shape.kind != b.shape.kind || (a.shape.size - b.shape.size).norm() > 1e-12 ||
        a.shape.mesh_path != b.shape.mesh_path || a.is_moving() != b.is_moving()) {
      return false;
    }
    // Poses are piecewise interpolated between samples: equal at both's samples, equal always.
    std::vector<double> times = {0.0};
    times.insert(times.end(), a.trajectory.times().begin(), a.trajectory.times().end());
    times.insert(times.end(), b.trajectory.times().begin(), b.trajectory.times().end());
    return std::all_of(times.begin(), times.end(), [&](double t) {
      return (a.pose_at(t).matrix() - b.pose_at(t).matrix()).norm() < 1e-9;
    });
  };
  for (SceneObstacle& o : after.obstacles) {
    const bool unchanged = std::any_of(
        before.obstacles.begin(), before.obstacles.end(),
        [&](const SceneObstacle& b) { return b.name == o.name && same(b.obstacle, o.obstacle); });
    if (!unchanged) {
      o.rgba = rgba;
      ++marked;
    }
  }
  return marked;
}

std::optional<Eigen::Vector3d> planar_axis(const dynamics::Model& model, const Eigen::VectorXd& q) {
  if (model.nq() == 0) return std::nullopt;
  dynamics::Data data(model);
  dynamics::forward_kinematics(model, data, q);
  std::optional<Eigen::Vector3d> axis;
  for (int i = 0; i < model.nq(); ++i) {
    const dynamics::Body& body = model.bodies[i];
    if (body.joint_type != dynamics::JointType::kRevolute) return std::nullopt;
    const Eigen::Vector3d a = (data.body_pose[i].linear() * body.screw_axis.head<3>()).normalized();
    if (!axis) {
      axis = a;
    } else if (axis->cross(a).norm() > 1e-6) {
      return std::nullopt;
    }
  }
  return axis;
}

}  // namespace kinograph::render

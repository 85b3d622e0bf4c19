#include "kinograph/fleet/neighbour_bodies.h"

#include <stdexcept>
#include <utility>

#include "kinograph/collision/shape.h"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"

namespace kinograph::fleet {
namespace {

// World pose of collision geometry g after forward kinematics on `data`; base geometry is posed
// in the world already (the model is placed at its base).
Eigen::Isometry3d geometry_pose(const dynamics::Geometry& g, const dynamics::Data& data) {
  return g.body < 0 ? g.origin : data.body_pose[g.body] * g.origin;
}

std::vector<NeighbourBody> empty_bodies(const Neighbour& neighbour, int first_id) {
  std::vector<NeighbourBody> bodies;
  const auto& geometry = neighbour.model->collision;
  bodies.reserve(geometry.size());
  for (size_t g = 0; g < geometry.size(); ++g) {
    NeighbourBody body;
    body.obstacle.id = first_id + static_cast<int>(g);
    body.obstacle.shape = collision::shape_of(geometry[g]);
    body.name = body_name(neighbour.name, geometry[g]);
    bodies.push_back(std::move(body));
  }
  return bodies;
}

void require_model(const Neighbour& neighbour) {
  if (!neighbour.model) {
    throw std::invalid_argument("neighbour '" + neighbour.name + "' has no robot model");
  }
}

}  // namespace

std::string body_name(const std::string& neighbour, const dynamics::Geometry& geometry) {
  return "neighbour '" + neighbour + "' link '" + geometry.link_name + "'";
}

double clock_offset(std::int64_t utime, std::int64_t origin_utime) {
  return static_cast<double>(utime - origin_utime) * 1e-6;
}

Eigen::VectorXd held_configuration(const planning::Plan& plan,
                                   planning::TrajectorySampler& sampler, double tau) {
  if (tau <= plan.t.front()) return plan.q.row(0).transpose();
  if (tau >= plan.t.back()) return plan.q.row(plan.q.rows() - 1).transpose();
  return sampler.at(tau).q;
}

std::vector<NeighbourBody> bodies_at(const Neighbour& neighbour, const Eigen::VectorXd& q,
                                     int first_id) {
  require_model(neighbour);
  const dynamics::Model& model = *neighbour.model;
  if (q.size() != model.nq() || !q.allFinite()) {
    throw std::invalid_argument("neighbour '" + neighbour.name + "': its state must be " +
                                std::to_string(model.nq()) + " finite joint positions, got " +
                                std::to_string(q.size()));
  }
  dynamics::Data data(model);
  dynamics::forward_kinematics(model, data, q);
  std::vector<NeighbourBody> bodies = empty_bodies(neighbour, first_id);
  for (size_t g = 0; g < bodies.size(); ++g) {
    bodies[g].obstacle.pose = geometry_pose(model.collision[g], data);
  }
  return bodies;
}

std::vector<double> sweep_times(const planning::Plan& plan, double offset,
                                int samples_per_interval) {
  if (samples_per_interval < 1) {
    throw std::invalid_argument("sweep: samples_per_interval must be >= 1");
  }
  std::vector<double> times;
  if (plan.t.empty()) return times;
  times.reserve((plan.t.size() - 1) * samples_per_interval + 1);
  for (size_t k = 0; k + 1 < plan.t.size(); ++k) {
    const double dt = plan.t[k + 1] - plan.t[k];
    for (int i = 0; i < samples_per_interval; ++i) {
      times.push_back(offset + plan.t[k] + dt * i / samples_per_interval);
    }
  }
  times.push_back(offset + plan.t.back());
  return times;
}

std::vector<NeighbourBody> bodies_along(const Neighbour& neighbour, const planning::Plan& plan,
                                        double offset, const std::vector<double>& times,
                                        int first_id) {
  require_model(neighbour);
  const dynamics::Model& model = *neighbour.model;
  std::unique_ptr<planning::TrajectorySampler> sampler;
  try {
    sampler = std::make_unique<planning::TrajectorySampler>(model, plan);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("neighbour '" + neighbour.name + "': " + e.what());
  }
  if (times.empty()) throw std::invalid_argument("neighbour '" + neighbour.name + "': no times");
  for (size_t i = 1; i < times.size(); ++i) {
    if (!(times[i] > times[i - 1])) {
      throw std::invalid_argument("neighbour '" + neighbour.name +
                                  "': sample times must increase strictly");
    }
  }
  std::vector<NeighbourBody> bodies = empty_bodies(neighbour, first_id);
  std::vector<std::vector<Eigen::Isometry3d>> poses(bodies.size());
  for (auto& p : poses) p.reserve(times.size());
  dynamics::Data data(model);
  for (const double t : times) {
    dynamics::forward_kinematics(model, data, held_configuration(plan, *sampler, t - offset));
    for (size_t g = 0; g < bodies.size(); ++g) {
      poses[g].push_back(geometry_pose(model.collision[g], data));
    }
  }
  for (size_t g = 0; g < bodies.size(); ++g) {
    if (model.collision[g].body < 0) {
      bodies[g].obstacle.pose = model.collision[g].origin;
    } else {
      bodies[g].obstacle.trajectory = collision::PoseTrajectory(times, std::move(poses[g]));
    }
  }
  return bodies;
}

std::vector<NeighbourBody> bodies_along(const Neighbour& neighbour, const planning::Plan& plan,
                                        double offset, const SweepOptions& options) {
  return bodies_along(neighbour, plan, offset,
                      sweep_times(plan, offset, options.samples_per_interval), options.first_id);
}

}  // namespace kinograph::fleet

#include "kinograph/fleet/joint_clearance.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "kinograph/collision/collision_world.h"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/fleet/neighbour_bodies.h"
#include "kinograph/planning/trajectory_sampler.h"

namespace kinograph::fleet {
namespace {

// The union of every robot's sample times on the common clock from `from` on (`from` itself
// included when finite), without near-duplicates (which would break PoseTrajectory's strictly
// increasing times).
std::vector<double> common_times(const std::vector<RobotPlan>& robots, int per_interval,
                                 double from, double to) {
  std::vector<double> times;
  if (std::isfinite(from) && from < to) times.push_back(from);
  for (const RobotPlan& r : robots) {
    for (const double t : sweep_times(r.plan, r.offset, per_interval)) {
      if (t >= from && t < to) times.push_back(t);
    }
  }
  std::sort(times.begin(), times.end());
  std::vector<double> unique;
  for (const double t : times) {
    if (unique.empty() || t - unique.back() > 1e-9) unique.push_back(t);
  }
  return unique;
}

}  // namespace

planning::Plan standing_plan(const Eigen::VectorXd& q, double duration) {
  planning::Plan p;
  p.t = {0.0, duration};
  p.q = p.qd = p.qdd = p.tau = Eigen::MatrixXd::Zero(2, q.size());
  p.q.row(0) = p.q.row(1) = q.transpose();
  return p;
}

std::string describe(const JointClearance& c) {
  std::ostringstream os;
  if (c.robot_a.empty()) return "no two robots have collision geometry";
  os << "robots '" << c.robot_a << "' (link '" << c.link_a << "') and '" << c.robot_b << "' (link '"
     << c.link_b << "') ";
  if (c.min_distance < 0) {
    os << "overlap by " << -c.min_distance << " m";
  } else {
    os << "are " << c.min_distance << " m apart";
  }
  os << " at t = " << c.t << " s";
  return os.str();
}

JointClearance joint_clearance(const std::vector<RobotPlan>& robots,
                               const JointClearanceOptions& options) {
  if (options.samples_per_interval < 1) {
    throw std::invalid_argument("joint clearance: samples_per_interval must be >= 1");
  }
  std::vector<std::unique_ptr<planning::TrajectorySampler>> samplers;
  for (size_t i = 0; i < robots.size(); ++i) {
    const RobotPlan& r = robots[i];
    if (!r.model) throw std::invalid_argument("robot '" + r.name + "' has no model");
    for (size_t j = 0; j < i; ++j) {
      if (robots[j].name == r.name) {
        throw std::invalid_argument("two robots are named '" + r.name + "'");
      }
    }
    try {
      samplers.push_back(std::make_unique<planning::TrajectorySampler>(*r.model, r.plan));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("robot '" + r.name + "': " + e.what());
    }
  }
  JointClearance result;
  const std::vector<double> times =
      common_times(robots, options.samples_per_interval, options.from, options.to);
  result.samples = static_cast<int>(times.size());
  if (times.empty()) return result;  // a window without a time of any plan in it
  // Robot i's bodies in a world whose obstacles are robot j's bodies along its plan, sampled at
  // the same common times, so both are posed exactly at every time checked.
  for (size_t i = 0; i < robots.size(); ++i) {
    const dynamics::Model& model = *robots[i].model;
    dynamics::Data data(model);
    for (size_t j = i + 1; j < robots.size(); ++j) {
      collision::CollisionWorldOptions world_options;
      world_options.base_vs_obstacles = true;
      collision::CollisionWorld world(model, world_options);
      const Neighbour other{robots[j].name, robots[j].model};
      for (const NeighbourBody& b : bodies_along(other, robots[j].plan, robots[j].offset, times)) {
        world.add_obstacle(b.obstacle);
      }
      for (const double t : times) {
        dynamics::forward_kinematics(
            model, data, held_configuration(robots[i].plan, *samplers[i], t - robots[i].offset));
        const collision::Proximity p = world.closest(data, t);
        if (p.robot_geom >= 0 && p.distance < result.min_distance) {
          result.min_distance = p.distance;
          result.t = t;
          result.robot_a = robots[i].name;
          result.link_a = model.collision[p.robot_geom].link_name;
          result.robot_b = robots[j].name;
          result.link_b = robots[j].model->collision[p.obstacle].link_name;
        }
      }
    }
  }
  return result;
}

}  // namespace kinograph::fleet

namespace kinograph::fleet {

JointClearance history_clearance(const std::vector<RobotHistory>& robots,
                                 const JointClearanceOptions& options, HistoryMemo* memo) {
  std::vector<double> cuts = {options.from};
  for (const RobotHistory& r : robots) {
    if (r.plans.empty()) throw std::invalid_argument("robot '" + r.name + "' has no plan");
    for (const RobotHistory::Piece& p : r.plans) {
      if (p.offset > options.from && p.offset < options.to) cuts.push_back(p.offset);
    }
  }
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  cuts.push_back(options.to);
  JointClearance closest;
  for (std::size_t w = 0; w + 1 < cuts.size(); ++w) {
    JointClearanceOptions window = options;
    window.from = cuts[w];
    window.to = cuts[w + 1];
    // Each robot's plan in force in the window: the latest of its list started by its beginning.
    std::ostringstream key;  // the window exactly, and the plans in force
    key << std::hexfloat << window.from << ' ' << window.to;
    std::vector<RobotPlan> in_force;
    for (const RobotHistory& r : robots) {
      std::size_t k = 0;
      for (std::size_t i = 0; i < r.plans.size(); ++i) {
        if (r.plans[i].offset <= window.from) k = i;
      }
      key << ' ' << k;
      in_force.push_back({r.name, r.model, r.plans[k].plan, r.plans[k].offset});
    }
    JointClearance c;
    if (memo && memo->count(key.str()) != 0) {
      c = memo->at(key.str());
    } else {
      c = joint_clearance(in_force, window);
      if (memo) (*memo)[key.str()] = c;
    }
    closest.samples += c.samples;
    if (c.min_distance < closest.min_distance) {
      const int samples = closest.samples;
      closest = c;
      closest.samples = samples;
    }
  }
  return closest;
}

}  // namespace kinograph::fleet

#include "kinograph/collision/segment_checker.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "kinograph/collision/convex_shape.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/graph/cancellation.h"

namespace kinograph::collision {
namespace {

// Largest distance a body's frame origin can be from its parent's: fixed for a revolute
// joint; a prismatic joint adds its travel (0 with a warning when unlimited).
double link_length(const dynamics::Body& body) {
  double len = body.parent_to_joint.translation().norm();
  if (body.joint_type == dynamics::JointType::kPrismatic) {
    const double travel = std::max(std::abs(body.limits.lower), std::abs(body.limits.upper));
    if (std::isfinite(travel)) {
      len += travel;
    } else {
      spdlog::warn(
          "segment checker: prismatic joint '{}' has no limits; its travel is not in "
          "the sweep bound",
          body.joint_name);
    }
  }
  return len;
}

}  // namespace

SegmentChecker::SegmentChecker(const dynamics::Model& model, SegmentCheckOptions options)
    : model_(model), options_(options), lever_(Eigen::VectorXd::Zero(model.nq())), q_(model.nq()) {
  // For each geometry, walk up its chain: the distance from joint j's axis point (body j's
  // origin) to any point of the geometry is at most the geometry's reach in its own body plus
  // the lengths of the links between.
  for (const dynamics::Geometry& g : model.collision) {
    if (g.body < 0) continue;
    const ConvexShape shape(shape_of(g));
    double reach = (g.origin * shape.bound_center()).norm() + shape.bound_radius();
    for (int b = g.body; b >= 0; b = model.bodies[b].parent) {
      const bool prismatic = model.bodies[b].joint_type == dynamics::JointType::kPrismatic;
      lever_[b] = std::max(lever_[b], prismatic ? 1.0 : reach);
      reach += link_length(model.bodies[b]);
    }
  }
}

int SegmentChecker::intervals(const Eigen::Ref<const Eigen::VectorXd>& q0,
                              const Eigen::Ref<const Eigen::VectorXd>& q1, double time_span) const {
  double max_step = 0, sweep = 0;
  for (int j = 0; j < model_.nq(); ++j) {
    const double dq = std::abs(q1[j] - q0[j]);
    max_step = std::max(max_step, dq);
    sweep += dq * lever_[j];
  }
  const double n = std::max({1.0, std::ceil(max_step / options_.max_joint_step),
                             std::ceil(sweep / options_.max_sweep_step),
                             std::ceil(std::abs(time_span) / options_.max_time_step)});
  return static_cast<int>(std::min(n, 1e6));
}

SegmentCheckResult SegmentChecker::check(CollisionWorld& world, dynamics::Data& data,
                                         const Eigen::Ref<const Eigen::VectorXd>& q0,
                                         const Eigen::Ref<const Eigen::VectorXd>& q1, double t0,
                                         double t1) {
  SegmentCheckResult result;
  result.min_distance = std::numeric_limits<double>::infinity();
  const int n = intervals(q0, q1, world.has_moving_obstacles() ? t1 - t0 : 0.0);
  for (int k = 0; k <= n; ++k) {
    const double s = static_cast<double>(k) / n;
    q_ = q0 + s * (q1 - q0);
    dynamics::forward_kinematics(model_, data, q_);
    const Proximity p = world.closest(data, t0 + s * (t1 - t0));
    if (p.distance < result.min_distance) {
      result.min_distance = p.distance;
      result.s = s;
      result.closest = p;
    }
  }
  result.samples = n + 1;
  return result;
}

PathCheckResult SegmentChecker::check_path(CollisionWorld& world, dynamics::Data& data,
                                           const Eigen::Ref<const Eigen::MatrixXd>& path,
                                           const std::vector<double>& times, double clearance) {
  PathCheckResult result;
  result.min_distance = result.lower_bound = std::numeric_limits<double>::infinity();
  const int m = static_cast<int>(path.rows());
  if (m == 0) return result;
  const bool moving = world.has_moving_obstacles();
  auto time_at = [&](int i, double u) {
    if (times.empty()) return 0.0;
    return i + 1 < m ? times[i] + u * (times[i + 1] - times[i]) : times[i];
  };
  // Any point moves at most the sweep; two points of the robot approach by at most twice it.
  const double relative = world.self_pairs().empty() ? 1.0 : 2.0;
  auto sweep_of = [&](int i) {
    return relative * (path.row(i + 1) - path.row(i)).cwiseAbs().dot(lever_.transpose());
  };
  auto sample = [&](int i, double u) {
    if (i + 1 < m) {
      q_ = path.row(i).transpose() + u * (path.row(i + 1) - path.row(i)).transpose();
    } else {
      q_ = path.row(i).transpose();
    }
    // A long walk (a fine plan's validation) must not hold up a daemon that stops its plan.
    graph::throw_if_cancelled();
    dynamics::forward_kinematics(model_, data, q_);
    ++result.samples;
    const Proximity p = world.closest(data, time_at(i, u));
    if (p.distance < result.min_distance) {
      result.min_distance = p.distance;
      result.segment = i;
      result.s = u;
      result.closest = p;
    }
    return p.distance;
  };

  int i = 0;     // current segment
  double u = 0;  // fraction along it
  double d = sample(0, 0);
  if (m == 1) {
    result.lower_bound = d;
    return result;
  }
  while (i < m - 1) {
    // Sweep budget to the next sample; with moving obstacles also a time budget.
    double budget = std::max(options_.max_sweep_step, d - clearance);
    double time_budget = moving ? options_.max_time_step : std::numeric_limits<double>::infinity();
    double swept = 0;
    while (i < m - 1) {
      const double seg_sweep = sweep_of(i);
      const double seg_time = std::abs(time_at(i, 1) - time_at(i, 0));
      const double left = 1 - u;
      // The fraction of this segment the budgets allow.
      double f = left;
      if (seg_sweep * left > budget) f = std::min(f, budget / seg_sweep);
      if (moving && seg_time * left > time_budget) f = std::min(f, time_budget / seg_time);
      budget -= seg_sweep * f;
      time_budget -= seg_time * f;
      swept += seg_sweep * f;
      if (f < left) {
        u += f;
        break;
      }
      ++i;
      u = 0;
      if (i == m - 1 || budget <= 0 || time_budget <= 0) break;
    }
    result.swept += swept / relative;
    if (result.samples >= options_.max_path_samples || result.swept > options_.max_path_sweep) {
      result.complete = false;
      result.stopped_segment = i;
      result.stopped_s = u;
      break;
    }
    const double next = sample(i, u);
    result.lower_bound = std::min(result.lower_bound, 0.5 * (d + next - swept));
    d = next;
  }
  result.lower_bound = std::min(result.lower_bound, result.min_distance);
  return result;
}

}  // namespace kinograph::collision

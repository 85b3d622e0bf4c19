#include "kinograph/collision/segment_checker.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "kinograph/collision/convex_shape.h"
#include "kinograph/dynamics/kinematics.h"

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

}  // namespace kinograph::collision

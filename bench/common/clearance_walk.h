#pragma once
// A benchmark's own measure of a plan's self and floor clearance, independent of the planner's
// factors and of the validator's adaptive walk: the cubic Hermite interpolant of the knots at a
// fixed number of points per interval, every self pair and the floor checked to the end.
#include <Eigen/Core>
#include <algorithm>
#include <limits>

#include "kinograph/collision/collision_world.h"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/clearance_world.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"

namespace kinograph::bench {

/// Smallest signed distance (m) between two checked links and between a link and the floor.
struct Clearance {
  double self = std::numeric_limits<double>::infinity();
  double floor = std::numeric_limits<double>::infinity();
};

/// The plan's self and floor clearance at `samples` + 1 points of every interval (no culling).
inline Clearance clearance_walk(const planning::Problem& problem, const planning::Plan& plan,
                                int samples) {
  const dynamics::Model& model = *problem.model;
  collision::CollisionWorldOptions self_only;
  self_only.self_collision = true;
  self_only.cull = false;
  self_only.self_collision_excluded = problem.self_and_floor.allowed_pairs;
  collision::CollisionWorld self(model, self_only);
  collision::CollisionWorldOptions floor_only;
  floor_only.cull = false;
  collision::CollisionWorld floor(model, floor_only);
  floor.add_obstacle(planning::floor_obstacle(problem.self_and_floor.floor.value_or(0.0)));
  dynamics::Data data(model);
  Clearance c;
  const double dt = problem.dt();
  for (int k = 0; k + 1 < plan.q.rows(); ++k) {
    for (int i = 0; i <= samples; ++i) {
      const double s = static_cast<double>(i) / samples, s2 = s * s, s3 = s2 * s;
      const Eigen::VectorXd q =
          ((2 * s3 - 3 * s2 + 1) * plan.q.row(k) + (s3 - 2 * s2 + s) * dt * plan.qd.row(k) +
           (-2 * s3 + 3 * s2) * plan.q.row(k + 1) + (s3 - s2) * dt * plan.qd.row(k + 1))
              .transpose();
      dynamics::forward_kinematics(model, data, q);
      c.self = std::min(c.self, self.closest(data).distance);
      c.floor = std::min(c.floor, floor.closest(data).distance);
    }
  }
  return c;
}

/// The same measure of one configuration.
inline Clearance clearance_at(const planning::Problem& problem, const Eigen::VectorXd& q) {
  planning::Plan still;
  still.q = q.transpose().replicate(2, 1);
  still.qd = Eigen::MatrixXd::Zero(2, q.size());
  return clearance_walk(problem, still, 1);
}

}  // namespace kinograph::bench

#pragma once
// A benchmark's own measure of a plan's dynamics between its knots, independent of the planner
// and the validator: inverse dynamics on the plan's interpolant at points inside every interval,
// q̇ and q̈ by central differences of the sampled q.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/trajectory_sampler.h"

namespace kinograph::bench {

/// Torque figures of a plan between its knots.
struct BetweenKnots {
  double shoulder = 0;      ///< max |τ| on the unactuated joints (N·m)
  double elbow_excess = 0;  ///< max (|τ| − effort) / effort of the actuated joints, ≥ 0
  double elbow_max = 0;     ///< max |τ| of the actuated joints (N·m)
};

/// Inverse dynamics at `points` times (i + ½)/points of every interval, on derivatives of the
/// sampled q taken over ±dt/200 (inside the interval, so no knot is straddled).
inline BetweenKnots measure_between_knots(const dynamics::Model& model, const planning::Plan& plan,
                                          int points) {
  planning::TrajectorySampler sampler(model, plan);
  dynamics::Data data(model);
  BetweenKnots m;
  for (int k = 0; k < sampler.intervals(); ++k) {
    const double dt = sampler.interval_length(k), e = dt / 200;
    for (int i = 0; i < points; ++i) {
      const double t = plan.t[k] + (i + 0.5) / points * dt;
      const Eigen::VectorXd qm = sampler.at(t - e).q, q0 = sampler.at(t).q,
                            qp = sampler.at(t + e).q;
      const Eigen::VectorXd qd = (qp - qm) / (2 * e), qdd = (qp - 2 * q0 + qm) / (e * e);
      const Eigen::VectorXd& tau = dynamics::rnea(model, data, q0, qd, qdd);
      for (int j = 0; j < model.nq(); ++j) {
        const dynamics::Body& b = model.bodies[j];
        if (!b.actuated) {
          m.shoulder = std::max(m.shoulder, std::abs(tau[j]));
        } else {
          m.elbow_max = std::max(m.elbow_max, std::abs(tau[j]));
          m.elbow_excess =
              std::max(m.elbow_excess, (std::abs(tau[j]) - b.limits.effort) / b.limits.effort);
        }
      }
    }
  }
  return m;
}

}  // namespace kinograph::bench

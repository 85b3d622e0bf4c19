#pragma once
// Samples a plan at any time on its interpolant (interpolant.h, docs/interpolation.md): the one
// function the validator, the renderer and an executor use to read a plan between its knots.
#include <vector>

#include "kinograph/dynamics/model.h"
#include "kinograph/planning/interpolant.h"
#include "kinograph/planning/plan.h"

namespace kinograph::planning {

/// A plan read through its interpolant. Borrows the model and the plan, which must outlive it;
/// keeps a workspace, so one sampler serves one thread.
class TrajectorySampler {
 public:
  /// Throws std::invalid_argument naming what does not fit: q, q̇, q̈ without one column per
  /// joint of `model`, fewer than two knots, or times that are missing or do not increase.
  TrajectorySampler(const dynamics::Model& model, const Plan& plan);

  /// q, q̇, q̈, τ at time t on the plan's clock, clamped to [t_0, t_N]. A knot's time reads the
  /// interval that starts there (the end of the last interval at t_N).
  InterpolantPoint at(double t);
  /// Points of interval k (knots k, k+1) at the given fractions of it (ascending, in [0, 1]).
  void interval(int k, const std::vector<double>& fractions, std::vector<InterpolantPoint>& out);
  /// Where interval k's interpolant arrives at t_{k+1} (before knot k+1 takes over); the gap to
  /// knot k+1 is the plan's continuity error there.
  InterpolantPoint interval_end(int k);

  /// Number of intervals (knots − 1).
  int intervals() const { return static_cast<int>(plan_.t.size()) - 1; }
  /// Length t_{k+1} − t_k of interval k (s).
  double interval_length(int k) const { return plan_.t[k + 1] - plan_.t[k]; }

 private:
  const Plan& plan_;
  IntervalInterpolant interpolant_;
  std::vector<double> times_;
  std::vector<InterpolantPoint> points_;
};

/// The plan sampled at `per_interval` evenly spaced points in every interval plus the last knot
/// (per_interval · N + 1 rows of q), with their times; for drawing and plotting.
struct SampledPath {
  std::vector<double> t;
  Eigen::MatrixXd q, qd, qdd, tau;
};
/// Throws as TrajectorySampler, and std::invalid_argument if per_interval < 1.
SampledPath sample_plan(const dynamics::Model& model, const Plan& plan, int per_interval);

}  // namespace kinograph::planning

#include "kinograph/planning/batch/interval_limits.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <vector>

#include "kinograph/graph/worker_local.h"
#include "kinograph/planning/interpolant.h"
#include "kinograph/planning/trajectory_sampler.h"

namespace kinograph::planning {
namespace {

// Whether x lies within `margin` of [lower, upper] or beyond it.
bool near(double x, double lower, double upper, double margin) {
  return x < lower + margin || x > upper - margin;
}

// The limits (IntervalLimitRows bits) the point comes within the margin of (the planner's
// tightened ones).
int limits_near(const dynamics::Model& model, const InterpolantPoint& p, double epsilon,
                double margin) {
  int bits = kNoLimitRows;
  for (int j = 0; j < model.nq(); ++j) {
    const dynamics::Body& b = model.bodies[j];
    const dynamics::JointLimits& l = b.limits;
    if (b.actuated && std::isfinite(l.effort) &&
        near(p.tau[j], -l.effort + epsilon, l.effort - epsilon, margin * l.effort)) {
      bits |= kEffortLimitRows;
    }
    if (std::isfinite(l.velocity) &&
        near(p.qd[j], -l.velocity + epsilon, l.velocity - epsilon, margin * l.velocity)) {
      bits |= kMotionLimitRows;
    }
    // Half-bounded joints measure the margin in radians (metres) of the one bound.
    const double range = std::isfinite(l.lower) && std::isfinite(l.upper) ? l.upper - l.lower : 1.0;
    if (near(p.q[j], l.lower + epsilon, l.upper - epsilon, margin * range)) {
      bits |= kMotionLimitRows;
    }
  }
  return bits;
}

}  // namespace

std::vector<char> intervals_near_limits(const Problem& problem, const Plan& plan, double margin) {
  const dynamics::Model& model = *problem.model;
  std::vector<char> flags(static_cast<size_t>(problem.steps), 0);
  const int checks = limit_points(problem.objectives.limit_substeps, problem.dt());
  if (checks == 0) return flags;
  // With unactuated joints every point already runs the dynamics: its torque rows cost next to
  // nothing more, and they keep the re-solve from pushing an effort over where it was clear.
  const bool underactuated = std::any_of(model.bodies.begin(), model.bodies.end(),
                                         [](const dynamics::Body& b) { return !b.actuated; });
  std::vector<double> fractions;
  for (int i = 1; i <= checks; ++i) fractions.push_back(static_cast<double>(i) / (checks + 1));
  // Intervals are independent: they are shared out, each worker with its own sampler.
  struct Workspace {
    TrajectorySampler sampler;
    std::vector<InterpolantPoint> points;
  };
  graph::WorkerLocal<Workspace> workspaces(
      [&] { return std::make_unique<Workspace>(Workspace{TrajectorySampler(model, plan), {}}); });
  std::vector<int> intervals(static_cast<size_t>(workspaces.local().sampler.intervals()));
  std::iota(intervals.begin(), intervals.end(), 0);
  auto one = [&](int k, int) {
    Workspace& w = workspaces.local();
    w.sampler.interval(k, fractions, w.points);
    int bits = kNoLimitRows;
    for (const InterpolantPoint& p : w.points) {
      bits |= limits_near(model, p, problem.objectives.limit_epsilon, margin);
      if (bits == kAllLimitRows) break;
    }
    flags[static_cast<size_t>(k)] =
        static_cast<char>(bits != kNoLimitRows && underactuated ? kAllLimitRows : bits);
  };
  graph::share_out(graph::kMaxWorkers, {}, intervals, one);
  return flags;
}

}  // namespace kinograph::planning

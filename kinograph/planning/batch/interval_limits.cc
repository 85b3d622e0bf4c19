#include "kinograph/planning/batch/interval_limits.h"

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

// Whether the point comes within the margin of a limit (the planner's tightened ones).
bool near_a_limit(const dynamics::Model& model, const InterpolantPoint& p, double epsilon,
                  double margin) {
  for (int j = 0; j < model.nq(); ++j) {
    const dynamics::Body& b = model.bodies[j];
    const dynamics::JointLimits& l = b.limits;
    if (b.actuated && std::isfinite(l.effort) &&
        near(p.tau[j], -l.effort + epsilon, l.effort - epsilon, margin * l.effort)) {
      return true;
    }
    if (std::isfinite(l.velocity) &&
        near(p.qd[j], -l.velocity + epsilon, l.velocity - epsilon, margin * l.velocity)) {
      return true;
    }
    // Half-bounded joints measure the margin in radians (metres) of the one bound.
    const double range = std::isfinite(l.lower) && std::isfinite(l.upper) ? l.upper - l.lower : 1.0;
    if (near(p.q[j], l.lower + epsilon, l.upper - epsilon, margin * range)) return true;
  }
  return false;
}

}  // namespace

std::vector<char> intervals_near_limits(const Problem& problem, const Plan& plan, double margin) {
  const dynamics::Model& model = *problem.model;
  std::vector<char> flags(static_cast<size_t>(problem.steps), 0);
  const int checks = limit_points(problem.objectives.limit_substeps, problem.dt());
  if (checks == 0) return flags;
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
    for (const InterpolantPoint& p : w.points) {
      if (near_a_limit(model, p, problem.objectives.limit_epsilon, margin)) {
        flags[static_cast<size_t>(k)] = 1;
        break;
      }
    }
  };
  graph::share_out(graph::kMaxWorkers, {}, intervals, one);
  return flags;
}

}  // namespace kinograph::planning

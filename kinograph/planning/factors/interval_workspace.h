#pragma once
// The interpolant scratch shared by the interval factors of one planning graph.
#include <memory>
#include <vector>

#include "kinograph/dynamics/model.h"
#include "kinograph/graph/worker_local.h"
#include "kinograph/planning/interpolant.h"

namespace kinograph::planning {

/// What an IntervalDynamicsFactor evaluation writes: the interpolant of its interval and the
/// points it reads from it. Sized by the largest factor that used it; allocates nothing after.
struct IntervalScratch {
  IntervalScratch(const dynamics::Model& model, double integration_step)
      : interpolant(model, integration_step) {}
  IntervalInterpolant interpolant;
  std::vector<InterpolantPoint> points;  // values at the check points, then Δt
  InterpolantPoint with_derivatives;     // one point's derivatives at a time
};

/// One IntervalScratch per worker thread (graph::WorkerLocal) for the interval factors of one
/// model and RK4 step, so that they may be evaluated in parallel without each holding its own
/// dynamics workspace. Keeps the model alive.
class IntervalWorkspace final : public graph::WorkerLocal<IntervalScratch> {
 public:
  IntervalWorkspace(std::shared_ptr<const dynamics::Model> model, double integration_step)
      : WorkerLocal([model, integration_step] {
          return std::make_unique<IntervalScratch>(*model, integration_step);
        }),
        model_(std::move(model)),
        integration_step_(integration_step) {}
  const std::shared_ptr<const dynamics::Model>& model() const { return model_; }
  double integration_step() const { return integration_step_; }

 private:
  std::shared_ptr<const dynamics::Model> model_;
  double integration_step_;
};

}  // namespace kinograph::planning

#include "kinograph/planning/batch/effort_continuation.h"

#include <cmath>
#include <memory>
#include <stdexcept>

namespace kinograph::planning {

bool effort_continuation_applies(const Problem& problem) {
  bool unactuated = false, limited = false;
  for (const dynamics::Body& b : problem.model->bodies) {
    unactuated = unactuated || !b.actuated;
    limited = limited || (b.actuated && std::isfinite(b.limits.effort));
  }
  return unactuated && limited;
}

Problem with_effort_scaled(const Problem& problem, double scale) {
  if (!(scale > 0) || !std::isfinite(scale)) {
    throw std::invalid_argument("effort continuation: scale factors must be positive");
  }
  Problem p = problem;
  auto model = std::make_shared<dynamics::Model>(*problem.model);
  for (dynamics::Body& b : model->bodies) {
    if (b.actuated && std::isfinite(b.limits.effort)) b.limits.effort *= scale;
  }
  p.model = std::move(model);
  return p;
}

}  // namespace kinograph::planning

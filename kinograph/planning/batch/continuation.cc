#include "kinograph/planning/batch/continuation.h"

#include <cmath>
#include <memory>
#include <stdexcept>

#include "kinograph/planning/batch/batch_planner.h"

namespace kinograph::planning {

Problem with_scaled_limits(const Problem& problem, double scale) {
  if (!(scale > 0) || !std::isfinite(scale)) {
    throw std::invalid_argument("limit scale must be positive and finite");
  }
  Problem p = problem;
  auto model = std::make_shared<dynamics::Model>(*problem.model);
  for (dynamics::Body& b : model->bodies) {
    if (std::isfinite(b.limits.effort)) b.limits.effort *= scale;
    if (std::isfinite(b.limits.velocity)) b.limits.velocity *= scale;
  }
  p.model = std::move(model);
  return p;
}

Plan plan_with_continuation(const BatchPlanner& planner, const Problem& problem,
                            const std::vector<double>& scales) {
  SolveStats total;
  total.attempts = 0;
  Plan last;
  bool have_last = false;
  const auto stage = [&](const Problem& p) {
    Plan plan = planner.plan(p, have_last ? &last : nullptr);
    total.iterations += plan.stats.iterations;
    total.outer_iterations += plan.stats.outer_iterations;
    total.linear_solves += plan.stats.linear_solves;
    total.attempts += plan.stats.attempts;
    total.solve_time_s += plan.stats.solve_time_s;
    // A refused or empty stage leaves nothing to start the next from.
    if (plan.q.rows() == p.steps + 1) {
      last = plan;
      have_last = true;
    }
    return plan;
  };
  for (double s : scales) stage(with_scaled_limits(problem, s));
  Plan plan = stage(problem);
  const SolveStats own = plan.stats;
  plan.stats = total;
  plan.stats.method = own.method;
  plan.stats.status = own.status;
  plan.stats.reason = own.reason;
  plan.stats.cost = own.cost;
  plan.stats.max_constraint_violation = own.max_constraint_violation;
  return plan;
}

}  // namespace kinograph::planning

#include "kinograph/planning/batch/grid_refinement.h"

#include <stdexcept>

#include "kinograph/planning/trajectory_sampler.h"

namespace kinograph::planning {

int coarser_grid(const Problem& problem, double max_interval) {
  if (!(max_interval > 0)) return 0;
  const int steps = problem.steps;
  for (int f = 2; f * f <= steps; ++f) {
    if (steps % f != 0) continue;
    // The slack keeps a grid of exactly max_interval (10 s in 100 steps) from rounding out.
    return problem.horizon / (steps / f) <= max_interval * (1 + 1e-9) ? steps / f : 0;
  }
  return 0;  // prime: no grid divides it
}

Trajectory refined_start(const Problem& fine, const Plan& coarse) {
  const int n = fine.model->nq(), intervals = static_cast<int>(coarse.q.rows()) - 1;
  if (coarse.q.cols() != n || intervals < 1 || fine.steps % intervals != 0) {
    throw std::invalid_argument(
        "grid refinement: the coarse plan's grid does not divide the steps");
  }
  const SampledPath path = sample_plan(*fine.model, coarse, fine.steps / intervals);
  Trajectory tr{path.q, path.qd, path.qdd};
  // The last knot is the coarse plan's own (its goal), not where its interpolant arrives.
  tr.q.row(fine.steps) = coarse.q.row(intervals);
  tr.qd.row(fine.steps) = coarse.qd.row(intervals);
  tr.qdd.row(fine.steps) = coarse.qdd.row(intervals);
  tr.q.row(0) = fine.start_q.transpose();
  if (fine.start_qd.size() == n) tr.qd.row(0) = fine.start_qd.transpose();
  return tr;
}

}  // namespace kinograph::planning

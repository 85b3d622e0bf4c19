#include "kinograph/graph/optimization_result.h"

namespace kinograph::graph {

std::string to_string(SolverStatus status) {
  switch (status) {
    case SolverStatus::kConverged:
      return "converged";
    case SolverStatus::kMaxIterations:
      return "max_iterations";
    case SolverStatus::kNoDecrease:
      return "no_decrease";
    case SolverStatus::kSingular:
      return "singular";
    case SolverStatus::kNonFinite:
      return "non_finite";
  }
  return "unknown";
}

}  // namespace kinograph::graph

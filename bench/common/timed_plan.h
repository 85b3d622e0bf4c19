#pragma once
// One batch plan with its wall time, as the planning benchmarks time it.
#include <chrono>

#include "kinograph/planning/batch/batch_planner.h"

namespace kinograph::bench {

/// A plan and the wall time of the whole BatchPlanner::plan call (build, solve, validate).
struct Run {
  planning::Plan plan;
  double wall_s = 0;
};

/// Plans `problem` once and times it.
inline Run plan_once(const planning::BatchPlanner& planner, const planning::Problem& problem) {
  const auto start = std::chrono::steady_clock::now();
  Run run;
  run.plan = planner.plan(problem);
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

}  // namespace kinograph::bench

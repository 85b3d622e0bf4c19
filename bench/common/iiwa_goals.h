#pragma once
// The seeded goals of the iiwa benchmarks (paper tasks 1 and 2): the goal sampler's settings and
// nearby goals for replanning, shared so every benchmark plans the same problems.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <random>

#include "kinograph/planning/goal_sampler.h"

namespace kinograph::bench {

/// Goal sampler settings: joints 0.2 rad inside their limits, the block (frame "payload") in the
/// box above and beside the desk, self-collision checked except the wrist pair (robots/README.md).
inline planning::GoalSamplerOptions iiwa_goal_options(std::uint64_t seed) {
  planning::GoalSamplerOptions o;
  o.seed = seed;
  o.limit_margin = 0.2;
  o.self_collision_excluded = {{4, 6}};
  o.region_frame = "payload";
  o.region = Eigen::AlignedBox3d(Eigen::Vector3d(0.3, -0.6, 0.75), Eigen::Vector3d(0.9, 0.6, 1.1));
  return o;
}

/// A new goal near `goal`: every joint moved uniformly within ±radius, kept only if the sampler
/// accepts it (limits, region, clearance, self-collision). Seeded; empty after 10000 tries.
inline std::optional<Eigen::VectorXd> nearby_goal(planning::GoalSampler& sampler,
                                                  const Eigen::VectorXd& goal, double radius,
                                                  std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-radius, radius);
  for (int t = 0; t < 10000; ++t) {
    Eigen::VectorXd q = goal;
    for (int j = 0; j < q.size(); ++j) q[j] += u(rng);
    if (sampler.accepts(q)) return q;
  }
  return std::nullopt;
}

}  // namespace kinograph::bench

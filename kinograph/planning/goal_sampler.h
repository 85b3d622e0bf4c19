#pragma once
// Seeded random joint goals for a scene (the 50-goal experiments of the paper's iiwa tasks).
//
// Generation: each candidate draws every joint uniformly from its position limits shrunk by
// `limit_margin` (joints with infinite limits from [-π, π]); it is kept only if (1) the frame
// `region_frame` (when set) lies inside `region`, (2) every robot body (payload included) is at
// least `clearance` from every obstacle and the problem's floor (obstacles at time `horizon`, where
// the goal is reached), and (3) no two non-adjacent robot bodies are closer than `self_clearance`
// (pairs listed in `self_collision_excluded` skipped). Candidates are drawn until one passes.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "kinograph/planning/problem.h"

namespace kinograph::collision {
class CollisionWorld;
}
namespace kinograph::dynamics {
class Data;
}

namespace kinograph::planning {

/// How goals are drawn; see the file comment for the procedure.
struct GoalSamplerOptions {
  std::uint64_t seed = 1;     ///< same seed, same goals (std::mt19937_64)
  double limit_margin = 0.2;  ///< rad (m for prismatic) kept inside each position limit
  /// Required obstacle clearance (m); negative means the problem's collision ε.
  double clearance = -1.0;
  bool self_collision = true;   ///< reject configurations whose bodies touch each other
  double self_clearance = 0.0;  ///< m, smallest gap between non-adjacent robot bodies
  /// Body-index pairs never checked for self-collision (the iiwa's wrist pair {4, 6}).
  std::vector<std::pair<int, int>> self_collision_excluded;
  /// Optional workspace region: the world position of this frame must lie in `region`.
  std::string region_frame;
  Eigen::AlignedBox3d region;
  int max_attempts = 200000;  ///< candidates drawn per goal before giving up
};

/// Draws collision-free joint goals within limits for one problem's robot and obstacles.
class GoalSampler {
 public:
  /// Keeps a reference to `problem`, which must outlive the sampler. Throws
  /// std::invalid_argument for a problem without a model or an unknown region frame.
  GoalSampler(const Problem& problem, GoalSamplerOptions options = {});
  ~GoalSampler();
  GoalSampler(const GoalSampler&) = delete;
  GoalSampler& operator=(const GoalSampler&) = delete;

  /// The next goal; empty if max_attempts candidates all failed.
  std::optional<Eigen::VectorXd> sample();
  /// `count` goals in order (fewer if sampling gave up).
  std::vector<Eigen::VectorXd> sample(int count);
  /// Whether q passes the sampler's checks (limits with margin, region, clearance).
  bool accepts(const Eigen::VectorXd& q);
  /// Candidates drawn so far (accepted and rejected).
  long attempts() const { return attempts_; }

 private:
  const Problem& problem_;
  GoalSamplerOptions options_;
  double clearance_ = 0;
  int region_frame_ = -1;
  std::mt19937_64 rng_;
  Eigen::VectorXd lo_, hi_;
  std::unique_ptr<dynamics::Data> data_;
  std::unique_ptr<collision::CollisionWorld> world_, self_world_;
  long attempts_ = 0;
};

}  // namespace kinograph::planning

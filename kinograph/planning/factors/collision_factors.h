#pragma once
// The collision hinge (the paper's c_sdf) as an inequality constraint: the signed distance of
// every (robot collision geometry, obstacle) pair stays at least ε, at each step and at states
// interpolated between steps (so thin obstacles are not jumped over).
#include <Eigen/Core>
#include <memory>
#include <vector>

#include "kinograph/collision/collision_world.h"
#include "kinograph/collision/distance_gradient.h"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/planning/factors/constrained_factor.h"

namespace kinograph::planning {

/// The collision scene shared by all collision factors of one graph (single-threaded use):
/// Bullet world with the problem's obstacles, a kinematics workspace, and the row of each
/// (robot geometry, obstacle) pair.
struct CollisionContext {
  /// Builds the world; throws std::invalid_argument if an obstacle id repeats or a shape is bad.
  CollisionContext(std::shared_ptr<const dynamics::Model> model,
                   const std::vector<collision::Obstacle>& obstacles, double query_distance);

  std::shared_ptr<const dynamics::Model> model;
  collision::CollisionWorld world;
  dynamics::Data data;
  collision::DistanceGradientWorkspace gradient_workspace;
  Eigen::VectorXd gradient;
  Eigen::VectorXd q;                     ///< the interpolated configuration
  std::vector<int> obstacle_ids;         ///< obstacle of each column of row_of
  std::vector<int> geoms;                ///< robot geometries that take part
  std::vector<std::vector<int>> row_of;  ///< [robot geometry][obstacle slot] → row, −1 if none
  int num_pairs = 0;
  double query_distance;
};

/// Signed distances d ≥ ε of every pair at the state q(s) between steps k and k+1 (s = 0: state
/// k exactly, keys q_k only; 0 < s < 1: the cubic Hermite interpolation of q_k, q̇_k, q_{k+1},
/// q̇_{k+1}, keys in that order). Pairs farther than the query distance read as that distance.
/// Obstacles are taken at time t = (k + s)Δt.
class CollisionFactor final : public ConstrainedFactor {
 public:
  CollisionFactor(int k, double s, double dt, double epsilon, double scale,
                  std::shared_ptr<CollisionContext> context);
  void compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
               const graph::Jacobians* J) const override;
  /// The time (s) of the state the rows are checked at.
  double time() const { return t_; }
  /// The collision scene, whose row_of names each row's (geometry, obstacle) pair.
  const CollisionContext& context() const { return *ctx_; }

 private:
  double s_, dt_, t_;
  Eigen::Vector4d h_;  // Hermite weights of q_k, Δt·q̇_k, q_{k+1}, Δt·q̇_{k+1}
  std::shared_ptr<CollisionContext> ctx_;
};

}  // namespace kinograph::planning

#pragma once
// The collision hinge (the paper's c_sdf) as an inequality constraint: the signed distance of
// every (robot collision geometry, obstacle) pair, and of every self-collision pair of two robot
// geometries, stays at least its ε, at each step and at states interpolated between steps (so
// thin obstacles are not jumped over).
#include <Eigen/Core>
#include <memory>
#include <vector>

#include "kinograph/collision/collision_world.h"
#include "kinograph/collision/distance_gradient.h"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/graph/worker_local.h"
#include "kinograph/planning/factors/constrained_factor.h"

namespace kinograph::planning {

/// Self-collision rows of a CollisionContext: the robot's non-adjacent geometry pairs.
struct SelfPairs {
  std::vector<std::pair<int, int>> allowed;  ///< body pairs never checked (−1 = the base)
  double epsilon = 0.01;                     ///< m, the hinge's safety distance of these rows
};

/// What one worker evaluates collision rows with: its own Bullet world (queries write the
/// world's caches) and kinematics workspace.
struct CollisionScratch {
  CollisionScratch(const dynamics::Model& model, const collision::CollisionWorldOptions& options);
  collision::CollisionWorld world;
  dynamics::Data data;
  collision::DistanceGradientWorkspace gradient_workspace;
  Eigen::VectorXd gradient;
  Eigen::VectorXd q;  ///< the interpolated configuration
};

/// The collision scene shared by all collision factors of one graph: the problem's obstacles
/// (and, with `self`, the robot's own pairs), the row of each (robot geometry, obstacle) pair,
/// then of each self pair, and a CollisionScratch per worker so that the factors may be
/// evaluated on several threads.
struct CollisionContext {
  /// Builds the world; throws std::invalid_argument if an obstacle id repeats or a shape is bad.
  /// `cull` false runs GJK on every pair: the reference the culled world must match exactly.
  CollisionContext(std::shared_ptr<const dynamics::Model> model,
                   const std::vector<collision::Obstacle>& obstacles, double query_distance,
                   const SelfPairs* self = nullptr, bool cull = true);
  CollisionContext(const CollisionContext&) = delete;
  CollisionContext& operator=(const CollisionContext&) = delete;

  /// Sets obstacle `id`'s fixed pose in every worker's world; fails for an unknown id. Not
  /// while the context's factors are being evaluated.
  collision::Status move_obstacle(int id, const Eigen::Isometry3d& pose);

  std::shared_ptr<const dynamics::Model> model;
  collision::CollisionWorldOptions world_options;
  std::vector<collision::Obstacle> obstacles;  ///< as now placed; each new world is built of them
  graph::WorkerLocal<CollisionScratch> scratch;
  std::vector<int> obstacle_ids;         ///< obstacle of each column of row_of
  std::vector<int> geoms;                ///< robot geometries that take part
  std::vector<std::vector<int>> row_of;  ///< [robot geometry][obstacle slot] → row, −1 if none
  /// [robot geometry][robot geometry] → row of a self pair (both orders), −1 if none.
  std::vector<std::vector<int>> self_row_of;
  int num_obstacle_rows = 0;  ///< rows 0..num_obstacle_rows−1 are obstacle pairs
  int num_pairs = 0;          ///< all rows, self pairs last
  double self_epsilon = 0.0;  ///< ε of the self rows
  double query_distance;
  /// Per joint, a bound on how fast any point of the robot's geometry moves with it (m/rad).
  Eigen::VectorXd lever;
  /// Whether an obstacle moves along a trajectory: no factor then stands in a past query.
  bool moving = false;
  /// Counts move_obstacle() calls: a past query stands only under the obstacles it saw.
  int version = 0;

  /// The row of a reported pair, −1 when it has none.
  int row(const collision::Proximity& p) const;
};

/// Signed distances d ≥ ε of every pair (self rows: d ≥ the context's self ε) at the state q(s)
/// between steps k and k+1 (s = 0: state k exactly, keys q_k only; 0 < s < 1: the cubic Hermite
/// interpolation of q_k, q̇_k, q_{k+1}, q̇_{k+1}, keys in that order). Pairs farther than the query
/// distance read as that distance; so do the pairs beyond their ε in an evaluation without
/// Jacobians while no multiplier is set (a cost or a violation: their hinges are off at any
/// distance). Obstacles are taken at time t = (k + s)Δt.
class CollisionFactor final : public ConstrainedFactor {
 public:
  CollisionFactor(int k, double s, double dt, double epsilon, double scale,
                  std::shared_ptr<CollisionContext> context);
  void compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
               const graph::Jacobians* J) const override;
  std::string describe_row(int row, double z, const RowContext& c) const override;
  bool parallel_safe() const override { return true; }  // a world per worker
  /// The time (s) of the state the rows are checked at.
  double time() const { return t_; }
  /// The collision scene, whose row_of names each row's (geometry, obstacle) pair.
  const CollisionContext& context() const { return *ctx_; }

 private:
  double s_, dt_, t_;
  // The distance up to which pairs are measured when only the hinges are asked for: the
  // largest ε of the rows (no further than the query distance).
  double hinge_query_distance_ = 0;
  Eigen::Vector4d h_;  // Hermite weights of q_k, Δt·q̇_k, q_{k+1}, Δt·q̇_{k+1}
  std::shared_ptr<CollisionContext> ctx_;
  // The last query of the world (at q, giving z), with the smallest z − ε over the rows.
  struct LastQuery {
    Eigen::VectorXd q, z;
    double gap = 0;
    int version = -1;
  };
  mutable LastQuery last_;  // a factor is evaluated by one thread at a time
};

}  // namespace kinograph::planning

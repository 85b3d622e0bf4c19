#pragma once
// The one trajectory interpolant of a plan between two knots (docs/interpolation.md): what the
// planner enforces, the validator checks, the renderer draws and an executor follows.
// - Actuated joints follow the cubic whose acceleration is linear from q̈_k to q̈_{k+1} (the
//   planner's collocation is exact for it).
// - Unactuated joints follow the robot's own dynamics along them (τ_u = 0, so
//   q̈_u = −M_uu⁻¹(M_ua q̈_a + h_u)), integrated by fixed-step RK4 from the state at knot k.
// For a fully actuated robot this is the plain cubic, and τ = RNEA(q, q̇, q̈) along it is the
// computed torque that executes it.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <vector>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/model.h"

namespace kinograph::planning {

/// Longest RK4 step (s) of the unactuated joints' integration: an interval of length Δt takes
/// integration_steps(Δt) equal steps. Part of the interpolant's definition, so an executor
/// that integrates the same way reproduces the plan exactly.
inline constexpr double kMaxIntegrationStep = 0.01;

/// Number of equal RK4 steps over an interval of length dt: ⌈dt / max_step⌉, ≥ 1.
int integration_steps(double dt, double max_step = kMaxIntegrationStep);

/// Interior points per interval of length dt where limits are enforced and checked: at least
/// `requested`, and at least one per RK4 node (so never more than kMaxIntegrationStep apart);
/// 0 when requested ≤ 0.
int limit_points(int requested, double dt);

/// The instants in (0, dt) where an actuated joint's cubic can peak, appended to `out`: where
/// its q̇ is zero (q turns back) and where its q̈ is zero (q̇ turns back). From the knot's q̇0
/// and q̈0 and the next knot's q̈1.
void actuated_turning_times(double qd0, double qdd0, double qdd1, double dt,
                            std::vector<double>& out);

/// The interpolant at one instant, s seconds after the interval's first knot: q, q̇, q̈ and
/// τ = RNEA(q, q̇, q̈) (zero on unactuated joints up to rounding). With derivatives, also their
/// derivatives (n × 4n each) with respect to the interval's inputs z = [q_k; q̇_k; q̈_k; q̈_{k+1}].
struct InterpolantPoint {
  double s = 0;
  Eigen::VectorXd q, qd, qdd, tau;
  Eigen::MatrixXd dq, dqd, dqdd, dtau;
};

/// The interpolant of one interval for one robot, with its own workspace (not thread-safe).
/// Allocates nothing once it has seen an interval of the same number of RK4 steps.
class IntervalInterpolant {
 public:
  /// Borrows `model`, which must outlive this. `max_step` is the longest RK4 step: the
  /// interpolant's kMaxIntegrationStep, or a longer one for the planner's coarse warm-up rows
  /// (an approximation of the interpolant, never what a plan is checked on). Such a coarse one
  /// reads a time between its nodes from the cubic Hermite of the nodes' states and slopes: one
  /// dynamics evaluation there instead of the five of a shorter RK4 step.
  explicit IntervalInterpolant(const dynamics::Model& model,
                               double max_step = kMaxIntegrationStep);

  /// Starts the interval from the knot (q0, qd0, qdd0) that ends, dt later, with acceleration
  /// qdd1: integrates the unactuated joints to every RK4 node, with their sensitivities when
  /// `derivatives`. Throws std::invalid_argument if a vector has not one entry per joint or
  /// dt ≤ 0.
  void start(const Eigen::Ref<const Eigen::VectorXd>& q0,
             const Eigen::Ref<const Eigen::VectorXd>& qd0,
             const Eigen::Ref<const Eigen::VectorXd>& qdd0,
             const Eigen::Ref<const Eigen::VectorXd>& qdd1, double dt, bool derivatives);
  /// The point s seconds into the started interval (s in [0, dt]: one shorter RK4 step from the
  /// node before s, or the nodes' Hermite when coarse). `derivatives` also fills the d* members and needs a start() with them.
  /// Without `with_tau`, τ and dτ are left as they were when every joint is actuated (the
  /// cubic then needs no dynamics), and dτ is not filled otherwise.
  /// Throws std::invalid_argument for s outside [0, dt] or derivatives without them.
  void at(double s, bool derivatives, InterpolantPoint& p, bool with_tau = true);

  /// Where the unactuated joints arrive at dt, y = [q_u; q̇_u] (joints in unactuated() order),
  /// and, after a start() with derivatives, dy/dz (2m × 4n): the shooting defect's ingredients
  /// without the inverse dynamics of a full point.
  const Eigen::VectorXd& end_state() const { return y_[steps_]; }
  const Eigen::MatrixXd& end_sensitivity() const { return S_[steps_]; }

  /// start() and at() for the times `s` (ascending, in [0, dt]); `out` is resized to match.
  void evaluate(const Eigen::Ref<const Eigen::VectorXd>& q0,
                const Eigen::Ref<const Eigen::VectorXd>& qd0,
                const Eigen::Ref<const Eigen::VectorXd>& qdd0,
                const Eigen::Ref<const Eigen::VectorXd>& qdd1, double dt,
                const std::vector<double>& s, bool derivatives, std::vector<InterpolantPoint>& out);

  /// Indices of the unactuated joints (integrated) and of the actuated ones (cubic).
  const std::vector<int>& unactuated() const { return unactuated_; }
  const std::vector<int>& actuated() const { return actuated_; }

 private:
  // The state at time s with the unactuated state y = [q_u; q̇_u] and its sensitivity S = dy/dz
  // (q, q̇, q̈ and with derivatives their d*); with_tau adds dτ, and τ when every joint is
  // actuated (with unactuated joints τ comes with their dynamics).
  void point(double s, const Eigen::VectorXd& y, const Eigen::MatrixXd& S, bool derivatives,
             bool with_tau, InterpolantPoint& p);
  // The slope ẏ = [q̇_u; q̈_u] at (s, y, S) into k and, with derivatives, its total derivative
  // dẏ/dz into dk.
  void slope(double s, const Eigen::VectorXd& y, const Eigen::MatrixXd& S, bool derivatives,
             Eigen::VectorXd& k, Eigen::MatrixXd& dk);
  // The unactuated state (and sensitivity) `rest` seconds after node `node` of a coarse
  // interpolant, from the cubic Hermite of its two nodes, into y_part_ and S_part_.
  void hermite(int node, double rest, bool derivatives);
  // One RK4 step of length len from (s, y, S) into (y1, S1).
  void rk4_step(double s, double len, const Eigen::VectorXd& y, const Eigen::MatrixXd& S,
                bool derivatives, Eigen::VectorXd& y1, Eigen::MatrixXd& S1);

  const dynamics::Model& model_;
  double max_step_;
  bool coarse_;  // max_step_ longer than the interpolant's: Hermite between the nodes
  dynamics::Data data_;
  std::vector<int> unactuated_, actuated_;
  // The current interval: inputs, RK4 step and the state (and sensitivity) at every node.
  Eigen::VectorXd q0_, qd0_, qdd0_, qdd1_;
  double dt_ = 0, h_ = 0;
  int steps_ = 0;
  bool derivatives_ = false;
  std::vector<Eigen::VectorXd> y_;
  std::vector<Eigen::MatrixXd> S_;
  // Coarse only: the slope at every node and its derivative, the last node's made when first
  // needed (end_slope_: 0 not yet, 1 without derivatives, 2 with).
  std::vector<Eigen::VectorXd> f_;
  std::vector<Eigen::MatrixXd> df_;
  int end_slope_ = 0;
  // Scratch.
  InterpolantPoint stage_;
  Eigen::VectorXd k_[4];
  Eigen::MatrixXd dk_[4];
  Eigen::VectorXd ys_, y_part_;
  Eigen::MatrixXd Ss_, S_part_;
  Eigen::MatrixXd rhs_;
};

}  // namespace kinograph::planning

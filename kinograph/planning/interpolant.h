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

/// Number of equal RK4 steps over an interval of length dt: ⌈dt / kMaxIntegrationStep⌉, ≥ 1.
int integration_steps(double dt);

/// Interior points per interval of length dt where limits are enforced and checked: at least
/// `requested`, and at least one per RK4 node (so never more than kMaxIntegrationStep apart);
/// 0 when requested ≤ 0.
int limit_points(int requested, double dt);

/// The interpolant at one instant, s seconds after the interval's first knot: q, q̇, q̈ and
/// τ = RNEA(q, q̇, q̈) (zero on unactuated joints up to rounding). With derivatives, also their
/// derivatives (n × 4n each) with respect to the interval's inputs z = [q_k; q̇_k; q̈_k; q̈_{k+1}].
struct InterpolantPoint {
  double s = 0;
  Eigen::VectorXd q, qd, qdd, tau;
  Eigen::MatrixXd dq, dqd, dqdd, dtau;
};

/// The interpolant of one interval for one robot, with its own workspace (not thread-safe).
class IntervalInterpolant {
 public:
  /// Borrows `model`, which must outlive this.
  explicit IntervalInterpolant(const dynamics::Model& model);

  /// The points at times `s` (ascending, in [0, dt]) of the interval that starts at the knot
  /// (q0, qd0, qdd0) and ends, dt later, with acceleration qdd1; `out` is resized to match.
  /// With `derivatives`, the d* members are filled too.
  void evaluate(const Eigen::Ref<const Eigen::VectorXd>& q0,
                const Eigen::Ref<const Eigen::VectorXd>& qd0,
                const Eigen::Ref<const Eigen::VectorXd>& qdd0,
                const Eigen::Ref<const Eigen::VectorXd>& qdd1, double dt,
                const std::vector<double>& s, bool derivatives, std::vector<InterpolantPoint>& out);

  /// Indices of the unactuated joints (integrated) and of the actuated ones (cubic).
  const std::vector<int>& unactuated() const { return unactuated_; }
  const std::vector<int>& actuated() const { return actuated_; }

 private:
  // The point at time s with the unactuated state y = [q_u; q̇_u] and its sensitivity S = dy/dz;
  // without with_tau (RK4 stages) τ and dτ are left stale.
  void point(double s, const Eigen::VectorXd& y, const Eigen::MatrixXd& S, bool derivatives,
             bool with_tau, InterpolantPoint& p);
  // One RK4 step of length len from (s, y, S) into (y1, S1).
  void rk4_step(double s, double len, const Eigen::VectorXd& y, const Eigen::MatrixXd& S,
                bool derivatives, Eigen::VectorXd& y1, Eigen::MatrixXd& S1);

  const dynamics::Model& model_;
  dynamics::Data data_;
  std::vector<int> unactuated_, actuated_;
  // The current interval's inputs.
  Eigen::VectorXd q0_, qd0_, qdd0_, qdd1_;
  double dt_ = 0;
  // Scratch.
  InterpolantPoint stage_;
  Eigen::VectorXd k_[4];
  Eigen::MatrixXd dk_[4];
  Eigen::VectorXd ys_;
  Eigen::MatrixXd Ss_;
  Eigen::VectorXd tau0_, tau0u_, fu_;
  Eigen::MatrixXd muu_, rhs_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
};

}  // namespace kinograph::planning

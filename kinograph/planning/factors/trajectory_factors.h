#pragma once
// Factors on the joint trajectory itself: the GP constant-acceleration prior between steps, the
// collocation constraints that make q, q̇, q̈ consistent, and the q/q̇/q̈ limit hinges.
#include <Eigen/Core>
#include <vector>

#include "kinograph/graph/factor.h"
#include "kinograph/planning/factors/constrained_factor.h"

namespace kinograph::planning {

/// Keys of the trajectory variables of state k: joint positions, velocities, accelerations.
graph::Key q_key(int k);
graph::Key v_key(int k);
graph::Key a_key(int k);

/// State transition Φ(Δt) of the constant-acceleration (white-noise-jerk) model of one joint,
/// state (q, q̇, q̈) (the paper's eq. phi_accel).
Eigen::Matrix3d gp_transition(double dt);
/// Covariance Q(Δt) = ∫₀^Δt e^{As} L Qc Lᵀ e^{Aᵀs} ds of one joint (L = [0 0 1]ᵀ):
/// Qc·[[Δt⁵/20, Δt⁴/8, Δt³/6], [Δt⁴/8, Δt³/3, Δt²/2], [Δt³/6, Δt²/2, Δt]] (the paper prints
/// ½Δt⁵ in the corner; Δt⁵/20 is the integral).
Eigen::Matrix3d gp_covariance(double dt, double qc);

/// GP prior between states k and k+1 of an n-joint arm: e_j = x_{k+1,j} − Φ x_{k,j} for each
/// joint's (q, q̇, q̈), whitened by Q⁻¹ (cost ½Σ_j e_jᵀQ⁻¹e_j). Keys q_k v_k a_k q_{k+1} v_{k+1}
/// a_{k+1}. Under exact collocation its cost is ∫ jerk²/Qc dt.
class GpPriorFactor final : public graph::Factor {
 public:
  GpPriorFactor(int k, int n, double dt, double qc);
  void evaluate(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const graph::Jacobians* J) const override;
  bool parallel_safe() const override { return true; }  // touches only its own state

 private:
  int n_;
  Eigen::Matrix3d phi_;
  Eigen::Matrix3d R_;  // upper triangular, RᵀR = Q⁻¹
};

/// Must-hold consistency of a piecewise-linear acceleration between states k and k+1:
///   q_{k+1} = q_k + q̇_k Δt + Δt²(2q̈_k + q̈_{k+1})/6,  q̇_{k+1} = q̇_k + Δt(q̈_k + q̈_{k+1})/2.
/// Linear, two equality rows per joint of `joints` (q rows first). Keys as GpPriorFactor.
class CollocationFactor final : public ConstrainedFactor {
 public:
  /// Rows are scaled by Δt² (positions) and Δt (velocities) so that both read as accelerations;
  /// `scale` multiplies those. `joints` are the joints that follow the cubic (empty: all n; the
  /// unactuated ones follow the dynamics instead, IntervalDynamicsFactor). Throws
  /// std::invalid_argument for a joint outside 0..n−1.
  CollocationFactor(int k, int n, double dt, double scale = 1.0, std::vector<int> joints = {});
  void compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
               const graph::Jacobians* J) const override;
  bool parallel_safe() const override { return true; }  // touches only its own state
  std::string describe_row(int row, double z, const RowContext& c) const override;

 private:
  int n_;
  double dt_;
  std::vector<int> joints_;
};

/// Box limits on one state's q, q̇, q̈ (the paper's c_limit as an inequality constraint): one
/// row per finite limit. Keys q_k v_k a_k.
class StateLimitFactor final : public ConstrainedFactor {
 public:
  /// Which variable (0 q, 1 q̇, 2 q̈) and joint each row limits, with its bounds.
  struct Limit {
    int variable = 0;
    int joint = 0;
    double lower = 0, upper = 0;
  };
  /// Throws std::invalid_argument if `limits` is empty.
  StateLimitFactor(int k, int n, std::vector<Limit> limits, double scale = 1.0);
  void compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
               const graph::Jacobians* J) const override;
  bool parallel_safe() const override { return true; }  // touches only its own state
  std::string describe_row(int row, double z, const RowContext& c) const override;
  /// What each row limits, in row order.
  const std::vector<Limit>& limits() const { return limits_; }

 private:
  std::vector<Limit> limits_;
};

}  // namespace kinograph::planning

#pragma once
// Inverse dynamics by the recursive Newton–Euler algorithm (MR §8.3.2, the paper's twist,
// acceleration, wrench and torque equations), its analytic derivatives, the mass matrix and
// forward dynamics.
//
// τ = M(q) q̈ + c(q, q̇) + g(q) + b ⊙ q̇ − Σ J_kᵀ F_ext,k: URDF joint damping b enters as + b q̇;
// gravity enters as a base twist acceleration of −g (no per-link gravity wrench).
#include <Eigen/Core>
#include <span>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/model.h"

namespace kinograph::dynamics {

/// A wrench [m; f] applied by the environment to a body, expressed in that body's frame
/// (moment about the body frame origin). A payload resting in the hand pushes down with m g.
struct ExternalWrench {
  int body = 0;
  Vector6 wrench = Vector6::Zero();
};

using VectorRef = Eigen::Ref<const Eigen::VectorXd>;

/// Joint torques τ(q, q̇, q̈) written to data.tau (returned); also fills data.body_pose and the
/// body-frame V, Vdot, F.
const Eigen::VectorXd& rnea(const Model& model, Data& data, const VectorRef& q, const VectorRef& qd,
                            const VectorRef& qdd, std::span<const ExternalWrench> ext = {});

/// τ and its exact derivatives: data.tau, data.dtau_dq = ∂τ/∂q, data.dtau_dqd = ∂τ/∂q̇
/// (damping included) and data.M = ∂τ/∂q̈. Also fills data.body_pose and V, Vdot, F.
void rnea_derivatives(const Model& model, Data& data, const VectorRef& q, const VectorRef& qd,
                      const VectorRef& qdd, std::span<const ExternalWrench> ext = {});

/// Joint-space mass matrix M(q) (composite rigid bodies), written to data.M (returned).
const Eigen::MatrixXd& mass_matrix(const Model& model, Data& data, const VectorRef& q);

/// Dynamics with passive joints: the accelerations of the joints `passive` (distinct indices)
/// that make their torques zero while the other joints accelerate as `qdd` says (its passive
/// entries are ignored), q̈_p = −M_pp⁻¹ τ_p(q̈_p = 0). Writes that q̈ to data.qdd, τ = RNEA(q,
/// q̇, q̈) (zero on the passive joints up to rounding) to data.tau and M(q) to data.M; with
/// `derivatives` also data.dtau_dq and data.dtau_dqd at that q̈, as rnea_derivatives. One
/// kinematics pass for all of it. M_pp must be positive definite. Allocates only when it meets
/// a passive set of a new size.
void passive_dynamics(const Model& model, Data& data, const VectorRef& q, const VectorRef& qd,
                      const VectorRef& qdd, std::span<const int> passive, bool derivatives,
                      std::span<const ExternalWrench> ext = {});

/// Forward dynamics: q̈ solving M q̈ = τ − (c + g + b q̇ − Σ J^T F_ext), written to data.qdd
/// (returned). M must be positive definite (every body with mass or inertia about its axis).
const Eigen::VectorXd& forward_dynamics(const Model& model, Data& data, const VectorRef& q,
                                        const VectorRef& qd, const VectorRef& tau,
                                        std::span<const ExternalWrench> ext = {});

}  // namespace kinograph::dynamics

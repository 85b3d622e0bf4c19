#pragma once
// The dynamic factor graph (DFG) of the paper (section IV-A): per body and time step, the twist,
// twist-acceleration, wrench-balance and torque factors, with link twists V, twist
// accelerations V̇, joint wrenches F and joint torques τ as graph variables.
//
// Conventions (Lynch & Park, Modern Robotics eqs. 8.45–8.49, body frames): for body i with
// parent λ and T_{λ,i}(q_i) = parent_to_joint · exp([A_i] q_i),
//   V_i  = Ad_{T_{i,λ}} V_λ + A_i q̇_i                                   (twist)
//   V̇_i  = Ad_{T_{i,λ}} V̇_λ + A_i q̈_i + [ad_{V_i}] A_i q̇_i              (acceleration)
//   F_i  = Σ_c Ad^T_{T_{c,i}} F_c + G_i V̇_i − [ad_{V_i}]^T G_i V_i − F_ext,i   (wrench)
//   τ_i  = A_i^T F_i + b_i q̇_i                                           (torque)
// with V_base = 0 and V̇_base = [0; −g] (gravity as a base acceleration), F_i the wrench the
// parent applies to body i through joint i, in body i's frame. The paper writes the same
// equations with the joint index shifted by one and −A q̇; the factors follow Lynch & Park, which
// is what dynamics::rnea computes, so RNEA's values satisfy every factor exactly.
//
// Every factor returns the raw error e = LHS − RHS with analytic Jacobians; the noise model
// (or a constraint method wrapping the factor) decides how hard it is enforced.
#include <Eigen/Core>
#include <vector>

#include "kinograph/dynamics/model.h"
#include "kinograph/dynamics/se3.h"
#include "kinograph/graph/factor.h"

namespace kinograph::planning {

/// A scalar joint quantity (q_j, q̇_j, q̈_j or τ_j) in the graph: either a variable of its own
/// (dim 1) or component `component` of a joint-vector variable of dimension `dim` (e.g. the
/// planner's q(0, k) holding all nq angles of step k).
struct JointScalar {
  graph::Key key;
  int dim = 1;
  int component = 0;
};

namespace detail {
/// Keys and dimensions of a DFG factor with repeated keys merged (built before the base class).
struct DfgLayout {
  std::vector<graph::Key> keys;
  std::vector<int> dims;
};
}  // namespace detail

/// Twist factor (MR eq. 8.45, the paper's eq. "twist"): e = V_i − Ad_{T_{i,λ}(q_i)} V_λ − A_i q̇_i
/// (6 rows). For a body whose parent is the base, V_λ = 0 and `V_parent` is ignored.
class DfgTwistFactor final : public graph::Factor {
 public:
  /// Throws std::invalid_argument for a body index out of range or a bad JointScalar.
  DfgTwistFactor(const dynamics::Model& model, int body, graph::Key V, graph::Key V_parent,
                 JointScalar q, JointScalar qd, graph::NoiseModelPtr noise = nullptr);

  void evaluate(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const graph::Jacobians* J) const override;
  bool parallel_safe() const override { return true; }  // touches only its own state

 private:
  DfgTwistFactor(detail::DfgLayout&& layout, const dynamics::Model& model, int body,
                 graph::Key V_parent, JointScalar q, JointScalar qd, graph::NoiseModelPtr noise);

  dynamics::Body body_;
  int slot_parent_;  // -1 when the parent is the base
  int slot_q_, slot_qd_;
  int comp_q_, comp_qd_;
};

/// Twist-acceleration factor (MR eq. 8.46, the paper's eq. "accel"):
/// e = V̇_i − Ad_{T_{i,λ}(q_i)} V̇_λ − A_i q̈_i − [ad_{V_i}] A_i q̇_i (6 rows). For a body whose parent
/// is the base, V̇_λ = [0; −model.gravity] (constant) and `Vdot_parent` is ignored.
class DfgAccelFactor final : public graph::Factor {
 public:
  /// Throws std::invalid_argument for a body index out of range or a bad JointScalar.
  DfgAccelFactor(const dynamics::Model& model, int body, graph::Key Vdot, graph::Key Vdot_parent,
                 graph::Key V, JointScalar q, JointScalar qd, JointScalar qdd,
                 graph::NoiseModelPtr noise = nullptr);

  void evaluate(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const graph::Jacobians* J) const override;
  bool parallel_safe() const override { return true; }  // touches only its own state

 private:
  DfgAccelFactor(detail::DfgLayout&& layout, const dynamics::Model& model, int body,
                 graph::Key Vdot_parent, graph::Key V, JointScalar q, JointScalar qd,
                 JointScalar qdd, graph::NoiseModelPtr noise);

  dynamics::Body body_;
  dynamics::Vector6 base_accel_;  // V̇ of the base, [0; −g]
  int slot_parent_;
  int slot_V_, slot_q_, slot_qd_, slot_qdd_;
  int comp_q_, comp_qd_, comp_qdd_;
};

/// One child of a body in the wrench balance: its wrench variable and its joint angle.
struct DfgChild {
  int body = 0;   ///< child body index in the Model
  graph::Key F;   ///< the child's wrench F_c
  JointScalar q;  ///< the child's joint angle q_c (sets T_{c,i})
};

/// Wrench-balance factor (MR eq. 8.47, the paper's eq. "wrench"):
/// e = F_i − Σ_c Ad^T_{T_{c,i}(q_c)} F_c − G_i V̇_i + [ad_{V_i}]^T G_i V_i + F_ext,i (6 rows),
/// summing over every child c of body i (a tree, not only a chain). F_ext is a constant wrench
/// the environment applies to body i, in its frame (dynamics::ExternalWrench convention).
class DfgWrenchFactor final : public graph::Factor {
 public:
  /// `children` must list exactly the Model's children of `body` (any order); throws
  /// std::invalid_argument otherwise.
  DfgWrenchFactor(const dynamics::Model& model, int body, graph::Key F, graph::Key Vdot,
                  graph::Key V, std::vector<DfgChild> children,
                  const dynamics::Vector6& external = dynamics::Vector6::Zero(),
                  graph::NoiseModelPtr noise = nullptr);

  void evaluate(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const graph::Jacobians* J) const override;
  bool parallel_safe() const override { return true; }  // touches only its own state

  /// The external wrench F_ext,i; may change between solves (structure unchanged).
  const dynamics::Vector6& external() const { return external_; }
  void set_external(const dynamics::Vector6& external) { external_ = external; }

 private:
  DfgWrenchFactor(detail::DfgLayout&& layout, const dynamics::Model& model, int body,
                  const std::vector<DfgChild>& children, const dynamics::Vector6& external,
                  graph::NoiseModelPtr noise);

  struct Child {
    dynamics::Body body;
    int slot_F, slot_q, comp_q;
  };
  dynamics::Matrix6 inertia_;
  dynamics::Vector6 external_;
  int slot_F_, slot_Vdot_, slot_V_;
  std::vector<Child> children_;
};

/// Torque factor (MR eq. 8.48, the paper's eq. "torque"): e = τ_i − A_i^T F_i − b_i q̇_i (1 row),
/// with b_i the joint's viscous damping so that τ matches dynamics::rnea. `qd` is a key of the
/// factor only when b_i ≠ 0.
class DfgTorqueFactor final : public graph::Factor {
 public:
  /// Throws std::invalid_argument for a body index out of range or a bad JointScalar.
  DfgTorqueFactor(const dynamics::Model& model, int body, JointScalar tau, graph::Key F,
                  JointScalar qd, graph::NoiseModelPtr noise = nullptr);

  void evaluate(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const graph::Jacobians* J) const override;
  bool parallel_safe() const override { return true; }  // touches only its own state

 private:
  DfgTorqueFactor(detail::DfgLayout&& layout, const dynamics::Model& model, int body,
                  JointScalar tau, graph::Key F, JointScalar qd, graph::NoiseModelPtr noise);

  dynamics::Vector6 A_;
  double damping_;
  int slot_tau_, slot_F_, slot_qd_;  // slot_qd_ = -1 without damping
  int comp_tau_, comp_qd_;
};

}  // namespace kinograph::planning

#include "kinograph/planning/factors/dfg_factors.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <stdexcept>
#include <string>

namespace kinograph::planning {
namespace {

using dynamics::Matrix6;
using dynamics::Vector6;
using graph::Key;

// Builds a factor's key list, merging repeated keys (several joint scalars may live in one
// joint-vector or state variable).
struct LayoutBuilder {
  detail::DfgLayout l;

  LayoutBuilder& add(Key key, int dim) {
    for (size_t i = 0; i < l.keys.size(); ++i) {
      if (l.keys[i] == key) {
        if (l.dims[i] != dim) {
          throw std::invalid_argument("DFG factor: key " + key.to_string() +
                                      " given with dimensions " + std::to_string(l.dims[i]) +
                                      " and " + std::to_string(dim));
        }
        return *this;
      }
    }
    l.keys.push_back(key);
    l.dims.push_back(dim);
    return *this;
  }
  LayoutBuilder& add(const JointScalar& s) {
    if (s.dim < 1 || s.component < 0 || s.component >= s.dim) {
      throw std::invalid_argument("DFG factor: joint scalar " + s.key.to_string() +
                                  " has component " + std::to_string(s.component) +
                                  " of dimension " + std::to_string(s.dim));
    }
    return add(s.key, s.dim);
  }
  detail::DfgLayout done() { return std::move(l); }
};

int slot_of(const std::vector<Key>& keys, Key key) {
  return static_cast<int>(std::find(keys.begin(), keys.end(), key) - keys.begin());
}

const dynamics::Body& checked_body(const dynamics::Model& model, int body) {
  if (body < 0 || body >= model.nq()) {
    throw std::invalid_argument("DFG factor: body index " + std::to_string(body) +
                                " out of range for a model with " + std::to_string(model.nq()) +
                                " bodies");
  }
  return model.bodies[body];
}

// T_{λ,i}(q) = parent_to_joint · exp([A] q) for a unit revolute or prismatic screw A.
Eigen::Isometry3d joint_transform(const dynamics::Body& b, double q) {
  Eigen::Isometry3d T;
  if (b.joint_type == dynamics::JointType::kRevolute) {
    const Eigen::Vector3d axis = b.screw_axis.head<3>();
    T.linear().noalias() =
        b.parent_to_joint.linear() * Eigen::AngleAxisd(q, axis).toRotationMatrix();
    T.translation() = b.parent_to_joint.translation();
  } else {
    T.linear() = b.parent_to_joint.linear();
    T.translation() =
        b.parent_to_joint.translation() + b.parent_to_joint.linear() * (b.screw_axis.tail<3>() * q);
  }
  return T;
}

// B(h) with [ad_X]^T h = B(h) X: the wrench bracket as a function of the twist X.
Matrix6 wrench_bracket(const Vector6& h) {
  Matrix6 B;
  const Eigen::Matrix3d m = dynamics::skew(h.head<3>());
  const Eigen::Matrix3d f = dynamics::skew(h.tail<3>());
  B << m, f, f, Eigen::Matrix3d::Zero();
  return B;
}

detail::DfgLayout twist_layout(const dynamics::Model& model, int body, Key V, Key V_parent,
                               JointScalar q, JointScalar qd) {
  LayoutBuilder l;
  l.add(V, 6);
  if (checked_body(model, body).parent >= 0) l.add(V_parent, 6);
  return l.add(q).add(qd).done();
}

detail::DfgLayout accel_layout(const dynamics::Model& model, int body, Key Vdot, Key Vdot_parent,
                               Key V, JointScalar q, JointScalar qd, JointScalar qdd) {
  LayoutBuilder l;
  l.add(Vdot, 6);
  if (checked_body(model, body).parent >= 0) l.add(Vdot_parent, 6);
  return l.add(V, 6).add(q).add(qd).add(qdd).done();
}

detail::DfgLayout wrench_layout(const dynamics::Model& model, int body, Key F, Key Vdot, Key V,
                                const std::vector<DfgChild>& children) {
  checked_body(model, body);
  std::vector<int> expected, given;
  for (int c = 0; c < model.nq(); ++c) {
    if (model.bodies[c].parent == body) expected.push_back(c);
  }
  for (const DfgChild& c : children) given.push_back(c.body);
  std::sort(given.begin(), given.end());
  if (given != expected) {
    throw std::invalid_argument("DFG wrench factor: the children given for body " +
                                std::to_string(body) + " (" + model.bodies[body].name +
                                ") are not its children in the model");
  }
  LayoutBuilder l;
  l.add(F, 6).add(Vdot, 6).add(V, 6);
  for (const DfgChild& c : children) l.add(c.F, 6).add(c.q);
  return l.done();
}

detail::DfgLayout torque_layout(const dynamics::Model& model, int body, JointScalar tau, Key F,
                                JointScalar qd) {
  LayoutBuilder l;
  l.add(tau).add(F, 6);
  if (checked_body(model, body).damping != 0.0) l.add(qd);
  return l.done();
}

}  // namespace

// ---------------------------------------------------------------------------------------------
DfgTwistFactor::DfgTwistFactor(const dynamics::Model& model, int body, Key V, Key V_parent,
                               JointScalar q, JointScalar qd, graph::NoiseModelPtr noise)
    : DfgTwistFactor(twist_layout(model, body, V, V_parent, q, qd), model, body, V_parent, q, qd,
                     std::move(noise)) {}

DfgTwistFactor::DfgTwistFactor(detail::DfgLayout&& layout, const dynamics::Model& model, int body,
                               Key V_parent, JointScalar q, JointScalar qd,
                               graph::NoiseModelPtr noise)
    : graph::Factor(std::move(layout.keys), std::move(layout.dims), 6, std::move(noise)),
      body_(model.bodies[body]),
      slot_parent_(body_.parent >= 0 ? slot_of(keys(), V_parent) : -1),
      slot_q_(slot_of(keys(), q.key)),
      slot_qd_(slot_of(keys(), qd.key)),
      comp_q_(q.component),
      comp_qd_(qd.component) {}

void DfgTwistFactor::evaluate(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                              const graph::Jacobians* J) const {
  const Vector6& A = body_.screw_axis;
  const double qd = x[slot_qd_][comp_qd_];
  // W = Ad_{T_{i,λ}} V_λ: the parent's twist seen in this body's frame (zero for the base).
  Vector6 W = Vector6::Zero();
  if (slot_parent_ >= 0) {
    const Eigen::Isometry3d T = joint_transform(body_, x[slot_q_][comp_q_]);
    W = dynamics::Ad_inv_apply(T, x[slot_parent_]);
    if (J != nullptr) {
      J->block(slot_parent_) = -dynamics::Ad_inv(T);
      // ∂(Ad_{T_{i,λ}(q)} V_λ)/∂q = −[ad_A] Ad_{T_{i,λ}} V_λ, since T_{i,λ} = exp(−[A]q) M⁻¹.
      J->block(slot_q_).col(comp_q_) += dynamics::ad_apply(A, W);
    }
  }
  e = x[0] - W - A * qd;
  if (J != nullptr) {
    J->block(0).setIdentity();
    J->block(slot_qd_).col(comp_qd_) -= A;
  }
}

// ---------------------------------------------------------------------------------------------
DfgAccelFactor::DfgAccelFactor(const dynamics::Model& model, int body, Key Vdot, Key Vdot_parent,
                               Key V, JointScalar q, JointScalar qd, JointScalar qdd,
                               graph::NoiseModelPtr noise)
    : DfgAccelFactor(accel_layout(model, body, Vdot, Vdot_parent, V, q, qd, qdd), model, body,
                     Vdot_parent, V, q, qd, qdd, std::move(noise)) {}

DfgAccelFactor::DfgAccelFactor(detail::DfgLayout&& layout, const dynamics::Model& model, int body,
                               Key Vdot_parent, Key V, JointScalar q, JointScalar qd,
                               JointScalar qdd, graph::NoiseModelPtr noise)
    : graph::Factor(std::move(layout.keys), std::move(layout.dims), 6, std::move(noise)),
      body_(model.bodies[body]),
      slot_parent_(body_.parent >= 0 ? slot_of(keys(), Vdot_parent) : -1),
      slot_V_(slot_of(keys(), V)),
      slot_q_(slot_of(keys(), q.key)),
      slot_qd_(slot_of(keys(), qd.key)),
      slot_qdd_(slot_of(keys(), qdd.key)),
      comp_q_(q.component),
      comp_qd_(qd.component),
      comp_qdd_(qdd.component) {
  base_accel_ << 0, 0, 0, -model.gravity;
}

void DfgAccelFactor::evaluate(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                              const graph::Jacobians* J) const {
  const Vector6& A = body_.screw_axis;
  const double qd = x[slot_qd_][comp_qd_];
  const double qdd = x[slot_qdd_][comp_qdd_];
  const Vector6 V = x[slot_V_];
  const Eigen::Isometry3d T = joint_transform(body_, x[slot_q_][comp_q_]);
  const Vector6 parent_accel = slot_parent_ >= 0 ? Vector6(x[slot_parent_]) : base_accel_;
  const Vector6 W = dynamics::Ad_inv_apply(T, parent_accel);  // Ad_{T_{i,λ}} V̇_λ
  const Vector6 adVA = dynamics::ad_apply(V, A);
  e = x[0] - W - A * qdd - adVA * qd;
  if (J != nullptr) {
    J->block(0).setIdentity();
    if (slot_parent_ >= 0) J->block(slot_parent_) = -dynamics::Ad_inv(T);
    // [ad_V] A = −[ad_A] V, so ∂e/∂V = q̇ [ad_A].
    J->block(slot_V_) = qd * dynamics::ad(A);
    J->block(slot_q_).col(comp_q_) += dynamics::ad_apply(A, W);
    J->block(slot_qd_).col(comp_qd_) -= adVA;
    J->block(slot_qdd_).col(comp_qdd_) -= A;
  }
}

// ---------------------------------------------------------------------------------------------
DfgWrenchFactor::DfgWrenchFactor(const dynamics::Model& model, int body, Key F, Key Vdot, Key V,
                                 std::vector<DfgChild> children, const Vector6& external,
                                 graph::NoiseModelPtr noise)
    : DfgWrenchFactor(wrench_layout(model, body, F, Vdot, V, children), model, body, children,
                      external, std::move(noise)) {
  slot_F_ = slot_of(keys(), F);
  slot_Vdot_ = slot_of(keys(), Vdot);
  slot_V_ = slot_of(keys(), V);
}

DfgWrenchFactor::DfgWrenchFactor(detail::DfgLayout&& layout, const dynamics::Model& model, int body,
                                 const std::vector<DfgChild>& children, const Vector6& external,
                                 graph::NoiseModelPtr noise)
    : graph::Factor(std::move(layout.keys), std::move(layout.dims), 6, std::move(noise)),
      inertia_(model.bodies[body].inertia),
      external_(external),
      slot_F_(0),
      slot_Vdot_(1),
      slot_V_(2) {
  children_.reserve(children.size());
  for (const DfgChild& c : children) {
    children_.push_back(
        {model.bodies[c.body], slot_of(keys(), c.F), slot_of(keys(), c.q.key), c.q.component});
  }
}

void DfgWrenchFactor::evaluate(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                               const graph::Jacobians* J) const {
  const Vector6 V = x[slot_V_];
  const Vector6 h = inertia_ * V;  // momentum G V
  Vector6 r = Vector6(x[slot_F_]) - inertia_ * Vector6(x[slot_Vdot_]) +
              dynamics::ad_transpose_apply(V, h) + external_;
  for (const Child& c : children_) {
    const Eigen::Isometry3d T = joint_transform(c.body, x[c.slot_q][c.comp_q]);  // T_{i,c}
    const Vector6 Fc = x[c.slot_F];
    r -= dynamics::Ad_inv_transpose_apply(T, Fc);  // Ad^T_{T_{c,i}} F_c
    if (J != nullptr) {
      J->block(c.slot_F) = -dynamics::Ad_inv(T).transpose();
      // ∂(Ad^T_{T_{c,i}(q)} F_c)/∂q = −Ad^T_{T_{c,i}} [ad_A]^T F_c.
      J->block(c.slot_q).col(c.comp_q) +=
          dynamics::Ad_inv_transpose_apply(T, dynamics::ad_transpose_apply(c.body.screw_axis, Fc));
    }
  }
  e = r;
  if (J != nullptr) {
    J->block(slot_F_).setIdentity();
    J->block(slot_Vdot_) = -inertia_;
    // ∂([ad_V]^T G V)/∂V = [ad_V]^T G + B(G V).
    J->block(slot_V_) = dynamics::ad(V).transpose() * inertia_ + wrench_bracket(h);
  }
}

// ---------------------------------------------------------------------------------------------
DfgTorqueFactor::DfgTorqueFactor(const dynamics::Model& model, int body, JointScalar tau, Key F,
                                 JointScalar qd, graph::NoiseModelPtr noise)
    : DfgTorqueFactor(torque_layout(model, body, tau, F, qd), model, body, tau, F, qd,
                      std::move(noise)) {}

DfgTorqueFactor::DfgTorqueFactor(detail::DfgLayout&& layout, const dynamics::Model& model, int body,
                                 JointScalar tau, Key F, JointScalar qd, graph::NoiseModelPtr noise)
    : graph::Factor(std::move(layout.keys), std::move(layout.dims), 1, std::move(noise)),
      A_(model.bodies[body].screw_axis),
      damping_(model.bodies[body].damping),
      slot_tau_(slot_of(keys(), tau.key)),
      slot_F_(slot_of(keys(), F)),
      slot_qd_(damping_ != 0.0 ? slot_of(keys(), qd.key) : -1),
      comp_tau_(tau.component),
      comp_qd_(qd.component) {}

void DfgTorqueFactor::evaluate(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                               const graph::Jacobians* J) const {
  const Vector6 F = x[slot_F_];
  e[0] = x[slot_tau_][comp_tau_] - A_.dot(F);
  if (slot_qd_ >= 0) e[0] -= damping_ * x[slot_qd_][comp_qd_];
  if (J != nullptr) {
    J->block(slot_tau_)(0, comp_tau_) += 1.0;
    J->block(slot_F_) -= A_.transpose();
    if (slot_qd_ >= 0) J->block(slot_qd_)(0, comp_qd_) -= damping_;
  }
}

}  // namespace kinograph::planning

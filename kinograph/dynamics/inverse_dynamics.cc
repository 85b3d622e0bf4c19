#include "kinograph/dynamics/inverse_dynamics.h"

#include "kinograph/dynamics/kinematics_detail.h"

namespace kinograph::dynamics {
namespace {

// World-frame spatial inertia of body i from its mass, COM and inertia about the COM.
void world_inertia(const Data::Scratch& s, int i, const Eigen::Isometry3d& T, Matrix6& I) {
  const double m = s.mass[i];
  const Eigen::Matrix3d& R = T.linear();
  const Eigen::Vector3d c = T.translation() + R * s.com[i];
  const Eigen::Matrix3d C = skew(c);
  const Eigen::Matrix3d mC = m * C;
  I.topLeftCorner<3, 3>().noalias() = R * s.Icom[i] * R.transpose();
  I.topLeftCorner<3, 3>().noalias() -= mC * C;
  I.topRightCorner<3, 3>() = mC;
  I.bottomLeftCorner<3, 3>() = -mC;
  I.bottomRightCorner<3, 3>() = m * Eigen::Matrix3d::Identity();
}

// External wrenches, moved to the world frame and summed per body.
void gather_external_world(const Model& model, Data& data, std::span<const ExternalWrench> ext) {
  auto& fext = data.scratch.fext;
  for (int i = 0; i < model.nq(); ++i) fext[i].setZero();
  for (const ExternalWrench& e : ext) {
    fext[e.body] += Ad_inv_transpose_apply(data.body_pose[e.body], e.wrench);
  }
}

// World-frame pass shared by the derivatives and the mass matrix: screws S_i, inertias I_i
// and composite inertias Ic_i (sum over the subtree of i). Poses must be current.
void world_screws_and_composites(const Model& model, Data& data) {
  const int n = model.nq();
  auto& s = data.scratch;
  for (int i = 0; i < n; ++i) {
    s.S[i] = Ad_apply(data.body_pose[i], model.bodies[i].screw_axis);
    world_inertia(s, i, data.body_pose[i], s.Iw[i]);
    s.Ic[i] = s.Iw[i];
  }
  for (int i = n - 1; i >= 0; --i) {
    const int p = model.bodies[i].parent;
    if (p >= 0) s.Ic[p] += s.Ic[i];
  }
}

}  // namespace

const Eigen::VectorXd& rnea(const Model& model, Data& data, const VectorRef& q, const VectorRef& qd,
                            const VectorRef& qdd, std::span<const ExternalWrench> ext) {
  const int n = model.nq();
  detail::update_poses(model, data, q);
  Vector6 a0;
  a0 << 0, 0, 0, -model.gravity;  // gravity as a base acceleration of −g

  // Forward: V_i = Ad_{T_i,λ} V_λ + A_i q̇_i, V̇_i = Ad_{T_i,λ} V̇_λ + [ad_{V_i}] A_i q̇_i + A_i q̈_i,
  // and each body's own wrench G V̇ − [ad_V]^T G V (MR eqs. 8.50–8.52).
  for (int i = 0; i < n; ++i) {
    const Body& b = model.bodies[i];
    const Eigen::Isometry3d& Tj = data.scratch.joint_pose[i];
    const Vector6& A = b.screw_axis;
    if (b.parent < 0) {
      data.V[i] = A * qd[i];
      data.Vdot[i] = Ad_inv_apply(Tj, a0) + A * qdd[i];
    } else {
      data.V[i] = Ad_inv_apply(Tj, data.V[b.parent]) + A * qd[i];
      data.Vdot[i] = Ad_inv_apply(Tj, data.Vdot[b.parent]) + A * qdd[i];
    }
    data.Vdot[i] += ad_apply(data.V[i], A) * qd[i];
    const Vector6 h = b.inertia * data.V[i];
    data.F[i].noalias() = b.inertia * data.Vdot[i];
    data.F[i] -= ad_transpose_apply(data.V[i], h);
  }
  for (const ExternalWrench& e : ext) data.F[e.body] -= e.wrench;
  // Backward: F_i += Σ_children Ad_{T_c,i}^T F_c, τ_i = A_i^T F_i + b_i q̇_i (MR eqs. 8.53–8.54).
  for (int i = n - 1; i >= 0; --i) {
    const Body& b = model.bodies[i];
    data.tau[i] = b.screw_axis.dot(data.F[i]) + b.damping * qd[i];
    if (b.parent >= 0) {
      data.F[b.parent] += Ad_inv_transpose_apply(data.scratch.joint_pose[i], data.F[i]);
    }
  }
  return data.tau;
}

namespace {

// World-frame geometry of q shared by the derivatives, the mass matrix and passive_dynamics:
// poses, screws, inertias, composites and the external wrenches in the world frame.
void world_geometry(const Model& model, Data& data, const VectorRef& q,
                    std::span<const ExternalWrench> ext) {
  detail::update_poses(model, data, q);
  world_screws_and_composites(model, data);
  gather_external_world(model, data, ext);
}

// M_ij = S_i^T Ic_i S_j for j an ancestor of i (or i): composite rigid bodies, from the
// current world geometry.
void mass_matrix_from_composites(const Model& model, Data& data) {
  const int n = model.nq();
  auto& s = data.scratch;
  for (int i = 0; i < n; ++i) s.SIc[i].noalias() = s.Ic[i] * s.S[i];
  data.M.setZero();
  for (int i = 0; i < n; ++i) {
    for (int j = i; j >= 0; j = model.bodies[j].parent) {
      data.M(i, j) = s.SIc[i].dot(s.S[j]);
      data.M(j, i) = data.M(i, j);
    }
  }
}

// The velocity half of the world-frame Newton–Euler pass on the current geometry: twists, Ṡ,
// β and each body's velocity wrench fv; with `for_derivatives` also the composites hc and Ec
// that derivative_assembly needs. None of it depends on q̈.
void world_velocity_pass(const Model& model, Data& data, const VectorRef& qd,
                         bool for_derivatives) {
  const int n = model.nq();
  auto& s = data.scratch;
  for (int i = 0; i < n; ++i) {
    const int p = model.bodies[i].parent;
    const Vector6 Vp = p < 0 ? Vector6::Zero() : s.Vw[p];
    const Vector6& S = s.S[i];
    s.Vw[i] = Vp + S * qd[i];
    s.Sdot[i] = ad_apply(s.Vw[i], S);
    s.beta[i] = ad_apply(S, Vp);
    const Matrix6& I = s.Iw[i];
    const Vector6 h = I * s.Vw[i];
    s.fv[i] = ad_transpose_apply(s.Vw[i], h) + s.fext[i];
    if (!for_derivatives) continue;
    s.hc[i] = h;
    // [ad_V]^T I column by column: three cross products a column, not a dense 6×6 product.
    for (int c = 0; c < 6; ++c) s.Ec[i].col(c) = ad_transpose_apply(s.Vw[i], I.col(c));
  }
  if (!for_derivatives) return;
  for (int i = n - 1; i >= 0; --i) {
    const int p = model.bodies[i].parent;
    if (p < 0) continue;
    s.hc[p] += s.hc[i];
    s.Ec[p] += s.Ec[i];
  }
}

// The acceleration half, after world_velocity_pass at the same q, q̇: accelerations, α,
// wrenches and their subtree sums Fw, and τ into data.tau.
void world_acceleration_pass(const Model& model, Data& data, const VectorRef& qd,
                             const VectorRef& qdd) {
  const int n = model.nq();
  auto& s = data.scratch;
  Vector6 a0;
  a0 << 0, 0, 0, -model.gravity;
  for (int i = 0; i < n; ++i) {
    const int p = model.bodies[i].parent;
    const Vector6 Vp = p < 0 ? Vector6::Zero() : s.Vw[p];
    const Vector6& ap = p < 0 ? a0 : s.aw[p];
    const Vector6& S = s.S[i];
    s.aw[i] = ap + s.Sdot[i] * qd[i] + S * qdd[i];
    s.alpha[i] = ad_apply(S, ap) + ad_apply(s.Sdot[i], Vp);
    s.fw[i].noalias() = s.Iw[i] * s.aw[i];
    s.fw[i] -= s.fv[i];
    s.Fw[i] = s.fw[i];
  }
  for (int i = n - 1; i >= 0; --i) {
    const int p = model.bodies[i].parent;
    if (p >= 0) s.Fw[p] += s.Fw[i];
  }
  for (int i = 0; i < n; ++i) data.tau[i] = s.S[i].dot(s.Fw[i]) + model.bodies[i].damping * qd[i];
}

// ∂τ/∂q, ∂τ/∂q̇ and M from the world passes at the same q, q̇; with `body_frame` also the
// body-frame V, V̇, F that rnea gives.
void derivative_assembly(const Model& model, Data& data, bool body_frame) {
  const int n = model.nq();
  auto& s = data.scratch;
  // Per body: rows S_i^T Ic_i, S_i^T Bc_i (Bc = Ec^T), S_i^T Dc_i (Dc = B(hc) + Ec, with
  // B(h) X = [ad_X]^T h the wrench bracket, so B(hc) X is one cross-product pair), and the
  // derivative of its own subtree wrench with respect to its own q_i and q̇_i.
  for (int i = 0; i < n; ++i) {
    const Vector6& S = s.S[i];
    const Vector6 BS = ad_transpose_apply(S, s.hc[i]);
    const Vector6 EtS = s.Ec[i].transpose() * S;
    s.SIc[i].noalias() = s.Ic[i] * S;
    s.SBc[i].noalias() = s.Ec[i] * S;
    s.SDc[i] = EtS - BS;  // Dc^T S, as B(h)^T = −B(h)
    s.dF_dq[i] = ad_transpose_apply(s.beta[i], s.hc[i]) - ad_transpose_apply(S, s.Fw[i]);
    s.dF_dq[i].noalias() -= s.Ic[i] * s.alpha[i];
    s.dF_dq[i].noalias() -= s.Ec[i].transpose() * s.Sdot[i];
    s.dF_dq[i].noalias() += s.Ec[i] * s.beta[i];
    s.dF_dqd[i].noalias() = s.Ic[i] * (s.Sdot[i] - s.beta[i]);
    s.dF_dqd[i] -= EtS + BS + s.SBc[i];  // Ec^T S + Dc S
  }
  data.dtau_dq.setZero();
  data.dtau_dqd.setZero();
  data.M.setZero();
  for (int i = 0; i < n; ++i) {
    for (int j = i; j >= 0; j = model.bodies[j].parent) {
      // j is i or an ancestor of i.
      data.dtau_dq(i, j) =
          -s.SIc[i].dot(s.alpha[j]) - s.SBc[i].dot(s.Sdot[j]) + s.SDc[i].dot(s.beta[j]);
      data.dtau_dqd(i, j) = s.SIc[i].dot(s.Sdot[j] - s.beta[j]) - (s.SBc[i] + s.SDc[i]).dot(s.S[j]);
      data.M(i, j) = s.SIc[i].dot(s.S[j]);
      if (j != i) {
        data.dtau_dq(j, i) = s.S[j].dot(s.dF_dq[i]);
        data.dtau_dqd(j, i) = s.S[j].dot(s.dF_dqd[i]);
        data.M(j, i) = data.M(i, j);
      }
    }
    data.dtau_dqd(i, i) += model.bodies[i].damping;
  }
  if (!body_frame) return;
  for (int i = 0; i < n; ++i) {
    data.V[i] = Ad_inv_apply(data.body_pose[i], s.Vw[i]);
    data.Vdot[i] = Ad_inv_apply(data.body_pose[i], s.aw[i]);
    data.F[i] = Ad_transpose_apply(data.body_pose[i], s.Fw[i]);
  }
}

}  // namespace

void rnea_derivatives(const Model& model, Data& data, const VectorRef& q, const VectorRef& qd,
                      const VectorRef& qdd, std::span<const ExternalWrench> ext) {
  // World-frame RNEA (S_i = Ad_{T_0i} A_i, twists add up along the chain, V̇ is the time
  // derivative of the spatial twist). Moving joint j moves every world quantity of its subtree
  // by the bracket with S_j, which gives the derivatives in closed form:
  //   ∂V_k/∂q_j = [S_j, V_k − V_λj],
  //   ∂a_k/∂q_j = [S_j, a_k − a_λj] + [Ṡ_j, V_k − V_λj],       Ṡ_j = [V_j, S_j],
  //   ∂a_k/∂q̇_j = Ṡ_j + [S_j, V_k − V_λj]                       (j an ancestor of k or k).
  // The wrench f_k = I_k a_k − ad_{V_k}^T I_k V_k − f_ext,k moves covariantly apart from the
  // parts of V and a inherited from λ(j); summing over subtrees leaves composites
  //   Ic = Σ I_k,  Ec = Σ ad_{V_k}^T I_k,  hc = Σ I_k V_k,
  // so every entry of ∂τ/∂q and ∂τ/∂q̇ is a few 6-vector dot products.
  world_geometry(model, data, q, ext);
  world_velocity_pass(model, data, qd, true);
  world_acceleration_pass(model, data, qd, qdd);
  derivative_assembly(model, data, true);
}

const Eigen::MatrixXd& mass_matrix(const Model& model, Data& data, const VectorRef& q) {
  detail::update_poses(model, data, q);
  world_screws_and_composites(model, data);
  mass_matrix_from_composites(model, data);
  return data.M;
}

void passive_dynamics(const Model& model, Data& data, const VectorRef& q, const VectorRef& qd,
                      const VectorRef& qdd, std::span<const int> passive, bool derivatives,
                      std::span<const ExternalWrench> ext) {
  const int m = static_cast<int>(passive.size());
  auto& s = data.scratch;
  world_geometry(model, data, q, ext);
  mass_matrix_from_composites(model, data);
  data.qdd = qdd;
  for (int a = 0; a < m; ++a) data.qdd[passive[a]] = 0;
  // The velocity half does not depend on q̈: it serves both acceleration passes below.
  world_velocity_pass(model, data, qd, derivatives);
  world_acceleration_pass(model, data, qd, data.qdd);
  // τ is affine in q̈ with slope M: τ_p(q̈_p) = τ0_p + M_pp q̈_p = 0.
  s.Mpp.resize(m, m);
  s.bias_p.resize(m);
  for (int a = 0; a < m; ++a) {
    s.bias_p[a] = -data.tau[passive[a]];
    for (int b = 0; b < m; ++b) s.Mpp(a, b) = data.M(passive[a], passive[b]);
  }
  s.llt_p.compute(s.Mpp);
  s.llt_p.solveInPlace(s.bias_p);
  for (int a = 0; a < m; ++a) {
    data.qdd[passive[a]] = s.bias_p[a];
    data.tau.noalias() += data.M.col(passive[a]) * s.bias_p[a];
  }
  if (!derivatives) return;
  world_acceleration_pass(model, data, qd, data.qdd);
  derivative_assembly(model, data, false);
}

const Eigen::VectorXd& forward_dynamics(const Model& model, Data& data, const VectorRef& q,
                                        const VectorRef& qd, const VectorRef& tau,
                                        std::span<const ExternalWrench> ext) {
  auto& s = data.scratch;
  s.bias = tau;  // copied first: tau may alias data.tau, which rnea overwrites
  data.qdd.setZero();
  rnea(model, data, q, qd, data.qdd, ext);
  s.bias -= data.tau;
  mass_matrix(model, data, q);
  s.llt.compute(data.M);
  data.qdd = s.bias;
  s.llt.solveInPlace(data.qdd);
  return data.qdd;
}

}  // namespace kinograph::dynamics

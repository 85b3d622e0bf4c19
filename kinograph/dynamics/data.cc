#include "kinograph/dynamics/data.h"

namespace kinograph::dynamics {

Data::Data(const Model& model) {
  const int n = model.nq();
  body_pose.assign(n, Eigen::Isometry3d::Identity());
  V.assign(n, Vector6::Zero());
  Vdot.assign(n, Vector6::Zero());
  F.assign(n, Vector6::Zero());
  tau = Eigen::VectorXd::Zero(n);
  qdd = Eigen::VectorXd::Zero(n);
  M = Eigen::MatrixXd::Zero(n, n);
  dtau_dq = Eigen::MatrixXd::Zero(n, n);
  dtau_dqd = Eigen::MatrixXd::Zero(n, n);

  Scratch& s = scratch;
  for (auto* v : {&s.S, &s.Sdot, &s.Vw, &s.aw, &s.fw, &s.Fw, &s.alpha, &s.beta, &s.dF_dq, &s.dF_dqd,
                  &s.SIc, &s.SBc, &s.SDc, &s.fext, &s.fv, &s.hc}) {
    v->assign(n, Vector6::Zero());
  }
  for (auto* m : {&s.Iw, &s.Ic, &s.Ec}) m->assign(n, Matrix6::Zero());
  s.joint_pose.assign(n, Eigen::Isometry3d::Identity());
  s.bias = Eigen::VectorXd::Zero(n);
  // Factor once to size the LLT's storage (copying a sized but unfactored LLT reads its
  // uninitialised status, which UBSan flags).
  s.llt.compute(Eigen::MatrixXd::Identity(n, n));
  s.llt_p.compute(Eigen::MatrixXd::Identity(1, 1));

  // G = [[Ī − m[c]², m[c]], [−m[c], m·1]] about the body origin; keep (m, c, Ī) to move the
  // inertia into the world frame with 3×3 products only.
  s.mass.resize(n);
  s.com.resize(n);
  s.Icom.resize(n);
  for (int i = 0; i < n; ++i) {
    const Matrix6& G = model.bodies[i].inertia;
    const double m = G(3, 3);
    s.mass[i] = m;
    if (m > 0) {
      const Eigen::Matrix3d mc = G.topRightCorner<3, 3>();
      s.com[i] = Eigen::Vector3d(mc(2, 1), mc(0, 2), mc(1, 0)) / m;
    } else {
      s.com[i].setZero();
    }
    const Eigen::Matrix3d C = skew(s.com[i]);
    s.Icom[i] = G.topLeftCorner<3, 3>() + m * C * C;
  }
}

}  // namespace kinograph::dynamics

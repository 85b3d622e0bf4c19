#pragma once
// Data: the mutable workspace of one Model. Allocated once; every algorithm writes into it
// and allocates nothing, so planners can call them in their inner loops.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "kinograph/dynamics/model.h"
#include "kinograph/dynamics/se3.h"

namespace kinograph::dynamics {

/// Workspace sized for one Model; results of the last algorithm call live here.
class Data {
 public:
  explicit Data(const Model& model);

  /// World pose of each body frame (after forward_kinematics, rnea, rnea_derivatives,
  /// mass_matrix or forward_dynamics).
  std::vector<Eigen::Isometry3d> body_pose;
  /// Body twist V, twist derivative V̇ (with the −g base acceleration folded in) and the wrench
  /// F transmitted through the joint from the parent, each in the body's own frame (after rnea
  /// or rnea_derivatives).
  std::vector<Vector6> V, Vdot, F;
  Eigen::VectorXd tau;       ///< joint torques/forces (rnea, rnea_derivatives)
  Eigen::VectorXd qdd;       ///< joint accelerations (forward_dynamics)
  Eigen::MatrixXd M;         ///< joint-space mass matrix (mass_matrix, rnea_derivatives)
  Eigen::MatrixXd dtau_dq;   ///< ∂τ/∂q (rnea_derivatives)
  Eigen::MatrixXd dtau_dqd;  ///< ∂τ/∂q̇, including the damping diagonal (rnea_derivatives)

  // Scratch of the algorithms (world-frame quantities); not part of the interface.
  struct Scratch {
    std::vector<Vector6> S, Sdot, Vw, aw, fw, Fw;     // screws, twists, accelerations, wrenches
    std::vector<Vector6> alpha, beta, dF_dq, dF_dqd;  // per-joint derivative seeds
    std::vector<Matrix6> Iw, Ic, Ec;                  // world inertias and composites
    std::vector<Vector6> SIc, SBc, SDc;               // S_i^T times the composites
    std::vector<Vector6> fext;                        // external wrenches per body
    std::vector<Vector6> fv;  // velocity part of each body's wrench: [ad_V]ᵀ I V + f_ext
    std::vector<Eigen::Isometry3d> joint_pose;        // T_parent,body(q)
    std::vector<double> mass;                         // body mass, COM and inertia about the
    std::vector<Eigen::Vector3d> com;                 // COM (body frame), split out of G once
    std::vector<Eigen::Matrix3d> Icom;
    std::vector<Vector6> hc;  // composite momenta
    Eigen::VectorXd bias;
    Eigen::LLT<Eigen::MatrixXd> llt;
    Eigen::MatrixXd Mpp;  // passive_dynamics: M of the passive joints, its LLT and right side
    Eigen::LLT<Eigen::MatrixXd> llt_p;
    Eigen::VectorXd bias_p;
  } scratch;
};

}  // namespace kinograph::dynamics

// Inverse dynamics against KDL's recursive Newton–Euler solvers, an independent library.
// The KDL chain/tree is built from the Model's joint placements, axes and inertias (mass, COM
// and inertia about the COM recovered from G). KDL has no joint damping: b q̇ is subtracted.
#include <gtest/gtest.h>

#include <kdl/chain.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/tree.hpp>
#include <kdl/treeidsolver_recursive_newton_euler.hpp>
#include <random>
#include <vector>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/dynamics/payload.h"
#include "test_util.h"

namespace kinograph::dynamics {
namespace {

KDL::Frame to_kdl(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d& R = T.linear();
  return KDL::Frame(KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0),
                                  R(2, 1), R(2, 2)),
                    KDL::Vector(T.translation().x(), T.translation().y(), T.translation().z()));
}

KDL::RigidBodyInertia to_kdl(const Matrix6& G) {
  const double m = G(3, 3);
  const Eigen::Matrix3d mc = G.topRightCorner<3, 3>();
  const Eigen::Vector3d c = Eigen::Vector3d(mc(2, 1), mc(0, 2), mc(1, 0)) / m;
  const Eigen::Matrix3d C = skew(c);
  const Eigen::Matrix3d Ic = G.topLeftCorner<3, 3>() + m * C * C;  // about the COM
  return KDL::RigidBodyInertia(
      m, KDL::Vector(c.x(), c.y(), c.z()),
      KDL::RotationalInertia(Ic(0, 0), Ic(1, 1), Ic(2, 2), Ic(0, 1), Ic(0, 2), Ic(1, 2)));
}

// Body i becomes two KDL segments: "fix<i>" (the constant parent_to_joint placement) and
// "body<i>" (the joint itself, tip frame = our body frame, carrying the inertia).
std::pair<KDL::Segment, KDL::Segment> segments(const Body& b, int i) {
  const Eigen::Vector3d axis =
      b.joint_type == JointType::kRevolute ? b.screw_axis.head<3>() : b.screw_axis.tail<3>();
  const KDL::Joint::JointType type =
      b.joint_type == JointType::kRevolute ? KDL::Joint::RotAxis : KDL::Joint::TransAxis;
  KDL::Segment fix("fix" + std::to_string(i), KDL::Joint(KDL::Joint::None),
                   to_kdl(b.parent_to_joint));
  KDL::Segment body("body" + std::to_string(i),
                    KDL::Joint(b.joint_name, KDL::Vector::Zero(),
                               KDL::Vector(axis.x(), axis.y(), axis.z()), type),
                    KDL::Frame::Identity(), to_kdl(b.inertia));
  return {fix, body};
}

KDL::Wrench to_kdl_wrench(const Vector6& w) {  // ours [m; f], KDL (force, torque)
  return KDL::Wrench(KDL::Vector(w[3], w[4], w[5]), KDL::Vector(w[0], w[1], w[2]));
}

// Copies into a JntArray without handing Eigen storage across the library boundary (a moved
// vector would be freed by code built with a different Eigen allocation setting than KDL's).
void fill(KDL::JntArray& a, const Eigen::VectorXd& v) {
  for (int i = 0; i < v.size(); ++i) a(i) = v[i];
}

Eigen::VectorXd damping_of(const Model& m) {
  Eigen::VectorXd b(m.nq());
  for (int i = 0; i < m.nq(); ++i) b[i] = m.bodies[i].damping;
  return b;
}

void compare_chain(const Model& model, bool with_wrench, std::mt19937& rng) {
  KDL::Chain chain;
  for (int i = 0; i < model.nq(); ++i) {
    ASSERT_EQ(model.bodies[i].parent, i - 1) << "serial chain expected";
    auto [fix, body] = segments(model.bodies[i], i);
    chain.addSegment(fix);
    chain.addSegment(body);
  }
  const Eigen::Vector3d g = model.gravity;
  KDL::ChainIdSolver_RNE solver(chain, KDL::Vector(g.x(), g.y(), g.z()));
  const int n = model.nq();
  Data data(model);
  const Eigen::VectorXd b = damping_of(model);
  for (int k = 0; k < 100; ++k) {
    KDL::JntArray q(n), qd(n), qdd(n), tau(n);
    fill(q, testing::random_vector(rng, n, 3.0));
    fill(qd, testing::random_vector(rng, n, 2.0));
    fill(qdd, testing::random_vector(rng, n, 5.0));
    KDL::Wrenches f_ext(chain.getNrOfSegments(), KDL::Wrench::Zero());
    std::vector<ExternalWrench> ext;
    if (with_wrench) {
      Vector6 w = testing::random_vector(rng, 6, 10.0);
      ext.push_back({n - 1, w});
      f_ext[2 * (n - 1) + 1] = to_kdl_wrench(w);
      w = testing::random_vector(rng, 6, 10.0);
      ext.push_back({2, w});
      f_ext[2 * 2 + 1] = to_kdl_wrench(w);
    }
    ASSERT_EQ(solver.CartToJnt(q, qd, qdd, f_ext, tau), 0);
    const Eigen::VectorXd ours = rnea(model, data, q.data, qd.data, qdd.data, ext);
    const Eigen::VectorXd kdl = tau.data + b.cwiseProduct(qd.data);
    EXPECT_LT((ours - kdl).norm(), 1e-9 * std::max(1.0, kdl.norm())) << ours.transpose() << "\n"
                                                                     << kdl.transpose();
    rnea_derivatives(model, data, q.data, qd.data, qdd.data, ext);
    EXPECT_LT((data.tau - kdl).norm(), 1e-9 * std::max(1.0, kdl.norm()));
  }
}

TEST(Kdl, IiwaInverseDynamics) {
  std::mt19937 rng(21);
  compare_chain(Model::from_urdf_file(testing::robot_path("iiwa14/iiwa14.urdf")), false, rng);
}

TEST(Kdl, IiwaWithPayloadAndExternalWrenches) {
  std::mt19937 rng(22);
  const Model iiwa = Model::from_urdf_file(testing::robot_path("iiwa14/iiwa14.urdf"));
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  offset.translation() << 0.0, 0.0, 0.05;
  offset.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Model loaded = attach_box_payload(iiwa, "iiwa_link_ee_kuka", 4.0, {0.2, 0.1, 0.1}, offset);
  compare_chain(loaded, false, rng);
  compare_chain(loaded, true, rng);
}

TEST(Kdl, IiwaPayloadEqualsAddingItsInertiaInKdl) {
  // Independent of attach_box_payload's arithmetic: add the block's inertia on the KDL side.
  const Model iiwa = Model::from_urdf_file(testing::robot_path("iiwa14/iiwa14.urdf"));
  const double mass = 2.5, a = 0.12, bb = 0.08, c = 0.06;
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  offset.translation() << 0.01, 0.0, 0.04;
  const Model loaded = attach_box_payload(iiwa, "iiwa_link_ee_kuka", mass, {a, bb, c}, offset);
  KDL::Chain chain;
  for (int i = 0; i < iiwa.nq(); ++i) {
    auto [fix, body] = segments(iiwa.bodies[i], i);
    chain.addSegment(fix);
    if (i == iiwa.nq() - 1) {
      // Flange at z = 0.045 on link 7 (reference), block centre offset from it.
      const KDL::RigidBodyInertia block(
          mass, KDL::Vector(0.01, 0.0, 0.045 + 0.04),
          KDL::RotationalInertia(mass / 12 * (bb * bb + c * c), mass / 12 * (a * a + c * c),
                                 mass / 12 * (a * a + bb * bb), 0, 0, 0));
      body = KDL::Segment(body.getName(), body.getJoint(), body.getFrameToTip(),
                          body.getInertia() + block);
    }
    chain.addSegment(body);
  }
  KDL::ChainIdSolver_RNE solver(chain, KDL::Vector(0, 0, -9.81));
  std::mt19937 rng(23);
  Data data(loaded);
  const Eigen::VectorXd b = damping_of(loaded);
  for (int k = 0; k < 100; ++k) {
    KDL::JntArray q(7), qd(7), qdd(7), tau(7);
    fill(q, testing::random_vector(rng, 7, 3.0));
    fill(qd, testing::random_vector(rng, 7, 2.0));
    fill(qdd, testing::random_vector(rng, 7, 5.0));
    KDL::Wrenches f_ext(chain.getNrOfSegments(), KDL::Wrench::Zero());
    ASSERT_EQ(solver.CartToJnt(q, qd, qdd, f_ext, tau), 0);
    const Eigen::VectorXd kdl = tau.data + b.cwiseProduct(qd.data);
    EXPECT_LT((rnea(loaded, data, q.data, qd.data, qdd.data) - kdl).norm(),
              1e-9 * std::max(1.0, kdl.norm()));
  }
}

TEST(Kdl, BranchingTreeInverseDynamics) {
  const Model model = Model::from_urdf_string(testing::kTreeUrdf);
  KDL::Tree tree("root");
  for (int i = 0; i < model.nq(); ++i) {
    auto [fix, body] = segments(model.bodies[i], i);
    const int p = model.bodies[i].parent;
    ASSERT_TRUE(tree.addSegment(fix, p < 0 ? "root" : "body" + std::to_string(p)));
    ASSERT_TRUE(tree.addSegment(body, fix.getName()));
  }
  ASSERT_EQ(static_cast<int>(tree.getNrOfJoints()), model.nq());
  std::vector<int> kdl_index(model.nq());
  for (int i = 0; i < model.nq(); ++i) {
    kdl_index[i] = tree.getSegment("body" + std::to_string(i))->second.q_nr;
  }
  KDL::TreeIdSolver_RNE solver(tree, KDL::Vector(0, 0, -9.81));
  std::mt19937 rng(24);
  const int n = model.nq();
  Data data(model);
  const Eigen::VectorXd b = damping_of(model);
  for (int k = 0; k < 100; ++k) {
    const Eigen::VectorXd q = testing::random_vector(rng, n, 2.0);
    const Eigen::VectorXd qd = testing::random_vector(rng, n, 2.0);
    const Eigen::VectorXd qdd = testing::random_vector(rng, n, 5.0);
    KDL::JntArray kq(n), kqd(n), kqdd(n), ktau(n);
    for (int i = 0; i < n; ++i) {
      kq(kdl_index[i]) = q[i];
      kqd(kdl_index[i]) = qd[i];
      kqdd(kdl_index[i]) = qdd[i];
    }
    const Vector6 w = testing::random_vector(rng, 6, 10.0);
    const std::vector<ExternalWrench> ext = {{3, w}};
    KDL::WrenchMap f_ext;
    f_ext["body3"] = to_kdl_wrench(w);
    ASSERT_EQ(solver.CartToJnt(kq, kqd, kqdd, f_ext, ktau), 0);
    Eigen::VectorXd kdl(n);
    for (int i = 0; i < n; ++i) kdl[i] = ktau(kdl_index[i]) + b[i] * qd[i];
    const Eigen::VectorXd ours = rnea(model, data, q, qd, qdd, ext);
    EXPECT_LT((ours - kdl).norm(), 1e-9 * std::max(1.0, kdl.norm())) << ours.transpose() << "\n"
                                                                     << kdl.transpose();
  }
}

}  // namespace
}  // namespace kinograph::dynamics

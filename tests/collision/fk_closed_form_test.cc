// Forward kinematics feeds every collision query. Revolute joints about a coordinate axis take a
// closed form (two columns of the joint's fixed rotation mix); it must agree bit for bit with
// the general axis-angle rotation, for ±x, ±y, ±z and for an oblique axis that keeps the
// general path.
#include <gtest/gtest.h>

#include <random>
#include <sstream>
#include <string>

#include "kinograph/dynamics/kinematics.h"

namespace kinograph::dynamics {
namespace {

// One link and the joint to it from the previous link (or the base).
std::string joint(int i, const char* axis, const char* rpy, const char* type = "revolute") {
  std::ostringstream os;
  os << "<link name=\"l" << i << "\"><inertial><mass value=\"1\"/><inertia ixx=\"0.01\" ixy=\"0\" "
     << "ixz=\"0\" iyy=\"0.01\" iyz=\"0\" izz=\"0.01\"/></inertial></link>"
     << "<joint name=\"j" << i << "\" type=\"" << type << "\"><parent link=\""
     << (i == 1 ? "base" : "l") << (i == 1 ? "" : std::to_string(i - 1)) << "\"/><child link=\"l"
     << i << "\"/><origin xyz=\"0.1 -0.05 0.2\" rpy=\"" << rpy << "\"/><axis xyz=\"" << axis
     << "\"/><limit lower=\"-3\" upper=\"3\" effort=\"10\" velocity=\"1\"/></joint>";
  return os.str();
}

TEST(ForwardKinematicsClosedForm, MatchesAxisAngleChainOnEveryAxis) {
  std::ostringstream urdf;
  urdf << "<?xml version=\"1.0\"?><robot name=\"axes\"><link name=\"base\"/>"
       << joint(1, "1 0 0", "0.3 -0.2 0.1") << joint(2, "0 -1 0", "0 0.4 0")
       << joint(3, "0 0 1", "1.2 0 -0.7") << joint(4, "0 0 -1", "0 0 0")
       << joint(5, "-1 0 0", "0.1 0.2 0.3") << joint(6, "0 1 0", "-0.5 0 0.2")
       << joint(7, "0.6 0 0.8", "0.2 0.1 0") << joint(8, "0 0 1", "0 0.3 0", "prismatic")
       << "</robot>";
  const Model model = Model::from_urdf_string(urdf.str());
  ASSERT_EQ(model.nq(), 8);
  Data data(model);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int trial = 0; trial < 50; ++trial) {
    Eigen::VectorXd q(model.nq());
    for (int j = 0; j < model.nq(); ++j) q[j] = u(rng);
    forward_kinematics(model, data, q);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    for (int i = 0; i < model.nq(); ++i) {
      const Body& b = model.bodies[i];
      ASSERT_EQ(b.parent, i - 1);
      // The general form, as forward kinematics composes it: P · R(axis, q), then parent · that.
      Eigen::Isometry3d J = b.parent_to_joint;
      if (b.joint_type == JointType::kRevolute) {
        J.linear().noalias() = b.parent_to_joint.linear() *
                               Eigen::AngleAxisd(q[i], b.screw_axis.head<3>()).toRotationMatrix();
      } else {
        J.translation() += b.parent_to_joint.linear() * (b.screw_axis.tail<3>() * q[i]);
      }
      if (i == 0) {
        T = J;
      } else {
        const Eigen::Matrix3d R = T.linear() * J.linear();
        T.translation() = T.translation() + T.linear() * J.translation();
        T.linear() = R;
      }
      SCOPED_TRACE("trial " + std::to_string(trial) + " body " + std::to_string(i));
      EXPECT_LT((data.body_pose[i].matrix() - T.matrix()).cwiseAbs().maxCoeff(), 1e-14);
      // Bit for bit, so that plans do not move when the closed form is taken.
      EXPECT_EQ(data.body_pose[i].linear(), T.linear());
      EXPECT_EQ(data.body_pose[i].translation(), T.translation());
    }
  }
}

}  // namespace
}  // namespace kinograph::dynamics

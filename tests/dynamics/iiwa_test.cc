// iiwa14 from robots/: structure read from the URDF, forward kinematics against the reference
// FK vectors, frames, Jacobians, and the block payload.
#include <gtest/gtest.h>

#include <cmath>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/dynamics/payload.h"
#include "test_util.h"

namespace kinograph::dynamics {
namespace {

using Vector7d = Eigen::Matrix<double, 7, 1>;

class IiwaTest : public ::testing::Test {
 protected:
  Model model = Model::from_urdf_file(testing::robot_path("iiwa14/iiwa14.urdf"));
  Data data{model};
  Eigen::Vector3d flange(const Vector7d& q) {
    forward_kinematics(model, data, q);
    return frame_pose(model, data, model.frame_index("iiwa_link_ee_kuka")).translation();
  }
};

TEST_F(IiwaTest, Structure) {
  ASSERT_EQ(model.nq(), 7);
  const double masses[] = {5.76, 6.35, 3.5, 3.5, 3.5, 1.8, 1.2};
  const double effort[] = {320, 320, 176, 176, 110, 40, 40};
  for (int i = 0; i < 7; ++i) {
    const Body& b = model.bodies[i];
    EXPECT_EQ(b.joint_name, "iiwa_joint_" + std::to_string(i + 1));
    EXPECT_EQ(b.name, "iiwa_link_" + std::to_string(i + 1));
    EXPECT_EQ(b.parent, i - 1);
    EXPECT_EQ(b.joint_type, JointType::kRevolute);
    EXPECT_DOUBLE_EQ(b.damping, 0.5);
    EXPECT_TRUE(b.actuated);
    EXPECT_NEAR(b.inertia(3, 3), masses[i], 1e-12);
    EXPECT_NEAR(b.limits.effort, effort[i], 1e-9);
    EXPECT_TRUE(std::isinf(b.limits.acceleration));
    EXPECT_NEAR(b.limits.upper, -b.limits.lower, 1e-12);
  }
  EXPECT_NEAR(model.bodies[0].limits.upper, 2.96706, 1e-5);
  EXPECT_NEAR(model.bodies[6].limits.velocity, 2.35619, 1e-5);
  EXPECT_EQ(model.body_index("iiwa_link_4"), 3);
  EXPECT_EQ(model.frames[model.frame_index("iiwa_link_0")].body, -1);
  EXPECT_EQ(model.frames[model.frame_index("iiwa_link_ee")].body, 6);
  EXPECT_THROW(model.frame_index("no_such_frame"), std::out_of_range);
  EXPECT_THROW(model.body_index("iiwa_link_0"), std::out_of_range);
  EXPECT_FALSE(model.collision.empty());
  EXPECT_FALSE(model.visual.empty());
}

TEST_F(IiwaTest, ForwardKinematicsAtZero) {
  const double z[] = {0.1575, 0.36, 0.5645, 0.78, 0.9645, 1.18, 1.261};
  const Eigen::Vector3d axes[] = {{0, 0, 1}, {0, 1, 0}, {0, 0, 1}, {0, -1, 0},
                                  {0, 0, 1}, {0, 1, 0}, {0, 0, 1}};
  forward_kinematics(model, data, Vector7d::Zero());
  Eigen::Matrix<double, 6, Eigen::Dynamic> J(6, 7);
  space_jacobian(model, data, 6, J);
  for (int i = 0; i < 7; ++i) {
    EXPECT_TRUE(data.body_pose[i].translation().isApprox(Eigen::Vector3d(0, 0, z[i]), 1e-9))
        << i << ": " << data.body_pose[i].translation().transpose();
    EXPECT_TRUE(J.col(i).head<3>().isApprox(axes[i], 1e-12)) << i;
  }
  EXPECT_TRUE(flange(Vector7d::Zero()).isApprox(Eigen::Vector3d(0, 0, 1.306), 1e-9));
  // iiwa_link_ee_kuka is the flange with identity orientation; iiwa_link_ee is pitched −π/2.
  const Eigen::Isometry3d kuka = frame_pose(model, data, model.frame_index("iiwa_link_ee_kuka"));
  const Eigen::Isometry3d ee = frame_pose(model, data, model.frame_index("iiwa_link_ee"));
  EXPECT_TRUE(kuka.linear().isIdentity(1e-9));
  EXPECT_TRUE(ee.linear().isApprox(
      Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix(), 1e-9));
}

TEST_F(IiwaTest, ForwardKinematicsReferenceVectors) {
  Vector7d q = Vector7d::Zero();
  q[1] = M_PI / 2;
  EXPECT_TRUE(flange(q).isApprox(Eigen::Vector3d(0.946, 0, 0.36), 1e-9)) << flange(q);
  q << 0.5, -0.3, 0.2, -1.0, 0.4, 0.8, -0.6;
  const Eigen::Vector3d p = flange(q);
  EXPECT_NEAR(p.x(), 0.149335, 1e-6);
  EXPECT_NEAR(p.y(), 0.223994, 1e-6);
  EXPECT_NEAR(p.z(), 1.075938, 1e-6);
}

TEST_F(IiwaTest, GravityTorquesAtZeroVanishForVerticalArm) {
  // Upright at q = 0 with every COM on or near the vertical axis; joints 1, 3, 5, 7 spin about
  // the vertical, so gravity cannot load them.
  const Eigen::VectorXd tau =
      rnea(model, data, Vector7d::Zero(), Vector7d::Zero(), Vector7d::Zero());
  for (int i : {0, 2, 4, 6}) EXPECT_NEAR(tau[i], 0.0, 1e-12) << i;
}

TEST_F(IiwaTest, BoxPayload) {
  const double mass = 2.0;
  const Eigen::Vector3d size(0.1, 0.06, 0.04);
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  offset.translation() << 0, 0, 0.02;
  const Model loaded = attach_box_payload(model, "iiwa_link_ee_kuka", mass, size, offset);
  EXPECT_NEAR(loaded.total_mass(), model.total_mass() + mass, 1e-12);
  EXPECT_EQ(loaded.collision.size(), model.collision.size() + 1);
  EXPECT_EQ(loaded.visual.size(), model.visual.size() + 1);
  const Frame& f = loaded.frames[loaded.frame_index("payload")];
  EXPECT_EQ(f.body, 6);
  EXPECT_TRUE(f.placement.translation().isApprox(Eigen::Vector3d(0, 0, 0.065), 1e-12));
  EXPECT_EQ(loaded.collision.back().shape, Geometry::Shape::kBox);
  EXPECT_TRUE(loaded.collision.back().size.isApprox(size));
  // A second payload gets a fresh frame name.
  const Model twice = attach_box_payload(loaded, "iiwa_link_7", 0.5, size, offset);
  EXPECT_NO_THROW(twice.frame_index("payload_2"));
  // Holding the arm horizontal, joint 2 carries the payload's extra weight times its lever arm.
  Vector7d q = Vector7d::Zero();
  q[1] = M_PI / 2;
  Data d2(loaded);
  const double extra = rnea(loaded, d2, q, Vector7d::Zero(), Vector7d::Zero())[1] -
                       rnea(model, data, q, Vector7d::Zero(), Vector7d::Zero())[1];
  EXPECT_NEAR(std::abs(extra), mass * 9.81 * (1.306 + 0.02 - 0.36), 1e-9);
  EXPECT_THROW(attach_box_payload(model, "nope", 1.0, size, offset), std::out_of_range);
  EXPECT_THROW(attach_box_payload(model, "iiwa_link_7", -1.0, size, offset), std::invalid_argument);
}

}  // namespace
}  // namespace kinograph::dynamics

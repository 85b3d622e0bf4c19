// place_base: a robot moved to a base pose is the same robot seen from a moved world — frames
// and geometry move rigidly, and its dynamics equal the original's under gravity expressed in
// the base frame.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "kinograph/dynamics/base_placement.h"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/kinematics.h"
#include "test_util.h"

namespace kinograph::dynamics {
namespace {

Eigen::Isometry3d tilted_base() {
  Eigen::Isometry3d base = Eigen::Isometry3d::Identity();
  base.translation() = Eigen::Vector3d(1.3, -0.4, 0.25);
  base.linear() = (Eigen::AngleAxisd(2.6, Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 1, 0).normalized()))
                      .toRotationMatrix();
  return base;
}

class BasePlacementTest : public ::testing::TestWithParam<const char*> {
 protected:
  Model load() const {
    const std::string which = GetParam();
    if (which == "tree") return Model::from_urdf_string(testing::kTreeUrdf);
    return Model::from_urdf_file(testing::robot_path(which));
  }
};

TEST_P(BasePlacementTest, FramesAndGeometryMoveRigidly) {
  const Model model = load();
  const Eigen::Isometry3d base = tilted_base();
  const Model placed = place_base(model, base);
  Data data(model), placed_data(placed);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd q(model.nq());
    for (int i = 0; i < q.size(); ++i) q[i] = u(rng);
    forward_kinematics(model, data, q);
    forward_kinematics(placed, placed_data, q);
    for (int f = 0; f < static_cast<int>(model.frames.size()); ++f) {
      const Eigen::Matrix4d expected = (base * frame_pose(model, data, f)).matrix();
      EXPECT_LT((frame_pose(placed, placed_data, f).matrix() - expected).cwiseAbs().maxCoeff(),
                1e-12)
          << model.frames[f].name;
    }
  }
  ASSERT_EQ(placed.collision.size(), model.collision.size());
  for (std::size_t g = 0; g < model.collision.size(); ++g) {
    const Geometry& before = model.collision[g];
    const Geometry& after = placed.collision[g];
    EXPECT_EQ(after.body, before.body);
    const Eigen::Isometry3d expected = before.body < 0 ? base * before.origin : before.origin;
    EXPECT_LT((after.origin.matrix() - expected.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST_P(BasePlacementTest, DynamicsEqualTheOriginalUnderGravityInTheBaseFrame) {
  const Model model = load();
  const Eigen::Isometry3d base = tilted_base();
  const Model placed = place_base(model, base);
  Model rotated_gravity = model;
  rotated_gravity.gravity = base.linear().transpose() * model.gravity;
  Data a(placed), b(rotated_gravity);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd q(model.nq()), qd(model.nq()), qdd(model.nq());
    for (int i = 0; i < q.size(); ++i) {
      q[i] = u(rng);
      qd[i] = u(rng);
      qdd[i] = u(rng);
    }
    const Eigen::VectorXd tau = rnea(placed, a, q, qd, qdd);
    const Eigen::VectorXd expected = rnea(rotated_gravity, b, q, qd, qdd);
    EXPECT_LT((tau - expected).cwiseAbs().maxCoeff(), 1e-9 * (1 + expected.cwiseAbs().maxCoeff()));
  }
}

INSTANTIATE_TEST_SUITE_P(Robots, BasePlacementTest,
                         ::testing::Values("tree", "iiwa14/iiwa14.urdf", "acrobot/acrobot.urdf"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           const std::string path = info.param;
                           return path.substr(0, path.find('/'));
                         });

TEST(BasePlacement, RefusesPosesThatAreNotRigid) {
  const Model model = Model::from_urdf_string(testing::kTreeUrdf);
  Eigen::Isometry3d scaled = Eigen::Isometry3d::Identity();
  scaled.linear() *= 2.0;
  EXPECT_THROW(place_base(model, scaled), std::invalid_argument);
  Eigen::Isometry3d mirrored = Eigen::Isometry3d::Identity();
  mirrored.linear()(2, 2) = -1.0;
  EXPECT_THROW(place_base(model, mirrored), std::invalid_argument);
  Eigen::Isometry3d nan = Eigen::Isometry3d::Identity();
  nan.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(place_base(model, nan), std::invalid_argument);
}

TEST(BasePlacement, IdentityLeavesTheModelAsItWas) {
  const Model model = Model::from_urdf_file(testing::robot_path("iiwa14/iiwa14.urdf"));
  EXPECT_TRUE(is_identity_pose(Eigen::Isometry3d::Identity()));
  EXPECT_FALSE(is_identity_pose(tilted_base()));
  const Model placed = place_base(model, Eigen::Isometry3d::Identity());
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    EXPECT_TRUE(placed.bodies[i].parent_to_joint.isApprox(model.bodies[i].parent_to_joint, 0));
  }
}

}  // namespace
}  // namespace kinograph::dynamics

// dynamics::compose against the robots one by one: every frame's pose, RNEA and the mass
// matrix (block-diagonal, each block the robot's own), names, and bad input.
#include "kinograph/dynamics/model_compose.h"

#include <gtest/gtest.h>

#include <random>

#include "kinograph/dynamics/base_placement.h"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/kinematics.h"

namespace kinograph::dynamics {
namespace {

const std::string kRobots = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/";

Eigen::Isometry3d pose(double x, double y, double yaw) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.translation() = Eigen::Vector3d(x, y, 0.1);
  p.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return p;
}

Eigen::VectorXd random_vector(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

class ComposeTest : public ::testing::Test {
 protected:
  Model iiwa = Model::from_urdf_file(kRobots + "iiwa14/iiwa14.urdf");
  Model acrobot = Model::from_urdf_file(kRobots + "acrobot/acrobot.urdf");
  std::vector<ComposedPart> parts{{"left", &iiwa, pose(-0.65, 0, 0)},
                                  {"right", &iiwa, pose(0.65, 0.1, M_PI)},
                                  {"pendulum", &acrobot, pose(0, 1.5, 0.3)}};
};

TEST_F(ComposeTest, FramesAndDynamicsEqualEachRobotsOwn) {
  std::vector<ComposedRange> ranges;
  const Model composite = compose(parts, &ranges);
  ASSERT_EQ(ranges.size(), 3u);
  EXPECT_EQ(composite.nq(), 2 * iiwa.nq() + acrobot.nq());
  std::mt19937 rng(7);
  Data cd(composite);
  for (int trial = 0; trial < 5; ++trial) {
    const int n = composite.nq();
    const Eigen::VectorXd q = random_vector(n, rng), qd = random_vector(n, rng),
                          qdd = random_vector(n, rng);
    forward_kinematics(composite, cd, q);
    const Eigen::VectorXd tau = rnea(composite, cd, q, qd, qdd);
    const Eigen::MatrixXd M = mass_matrix(composite, cd, q);
    for (std::size_t r = 0; r < parts.size(); ++r) {
      const ComposedRange& range = ranges[r];
      const Model placed = place_base(*parts[r].model, parts[r].world_from_base);
      Data d(placed);
      const Eigen::VectorXd qr = q.segment(range.offset, range.nq);
      forward_kinematics(placed, d, qr);
      for (std::size_t f = 0; f < placed.frames.size(); ++f) {
        const int cf = composite.frame_index(composed_name(range.name, placed.frames[f].name));
        EXPECT_TRUE(frame_pose(composite, cd, cf).isApprox(frame_pose(placed, d, f), 1e-12))
            << range.name << " frame " << placed.frames[f].name;
      }
      const Eigen::VectorXd tau_r = rnea(placed, d, qr, qd.segment(range.offset, range.nq),
                                         qdd.segment(range.offset, range.nq));
      EXPECT_LT((tau.segment(range.offset, range.nq) - tau_r).cwiseAbs().maxCoeff(), 1e-9)
          << range.name;
      const Eigen::MatrixXd M_r = mass_matrix(placed, d, qr);
      EXPECT_LT((M.block(range.offset, range.offset, range.nq, range.nq) - M_r).norm(), 1e-9);
      // No robot's joints move another's bodies: the off-diagonal blocks are zero.
      for (std::size_t o = 0; o < parts.size(); ++o) {
        if (o == r) continue;
        EXPECT_EQ(M.block(range.offset, ranges[o].offset, range.nq, ranges[o].nq).norm(), 0.0);
      }
    }
  }
}

TEST_F(ComposeTest, NamesArePrefixedAndGeometryKept) {
  std::vector<ComposedRange> ranges;
  const Model composite = compose(parts, &ranges);
  EXPECT_EQ(composite.bodies[0].joint_name, "left/iiwa_joint_1");
  EXPECT_EQ(composite.bodies[7].joint_name, "right/iiwa_joint_1");
  EXPECT_EQ(composite.bodies[7].parent, -1);
  EXPECT_EQ(composite.bodies[8].parent, 7);
  EXPECT_EQ(composite.bodies[14].name, "pendulum/" + acrobot.bodies[0].name);
  for (int b = 0; b < composite.nq(); ++b) EXPECT_LT(composite.bodies[b].parent, b);
  EXPECT_EQ(composite.collision.size(), 2 * iiwa.collision.size() + acrobot.collision.size());
  EXPECT_EQ(composite.visual.size(), 2 * iiwa.visual.size() + acrobot.visual.size());
  EXPECT_EQ(ranges[1].collision_offset, static_cast<int>(iiwa.collision.size()));
  const Geometry& g = composite.collision[ranges[1].collision_offset];
  EXPECT_EQ(g.link_name, "right/" + iiwa.collision[0].link_name);
  EXPECT_EQ(g.body, iiwa.collision[0].body < 0 ? -1 : iiwa.collision[0].body + 7);
  EXPECT_DOUBLE_EQ(composite.base_mass, 2 * iiwa.base_mass + acrobot.base_mass);
  EXPECT_NO_THROW(composite.frame_index("right/iiwa_link_ee"));
}

TEST_F(ComposeTest, BadInputIsRefusedNamingTheRobot) {
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  const auto message = [](const std::vector<ComposedPart>& p) {
    try {
      compose(p);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message({}).find("at least one robot"), std::string::npos);
  EXPECT_NE(message({{"a", &iiwa, I}, {"a", &iiwa, I}}).find("two robots are named 'a'"),
            std::string::npos);
  EXPECT_NE(message({{"a/b", &iiwa, I}}).find("must not contain '/'"), std::string::npos);
  EXPECT_NE(message({{"a", nullptr, I}}).find("robot 'a' has no model"), std::string::npos);
  Model moon = iiwa;
  moon.gravity = Eigen::Vector3d(0, 0, -1.62);
  EXPECT_NE(message({{"a", &iiwa, I}, {"b", &moon, I}}).find("robot 'b' has a gravity"),
            std::string::npos);
  Eigen::Isometry3d skew = Eigen::Isometry3d::Identity();
  skew.linear()(0, 1) = 0.5;
  EXPECT_NE(message({{"a", &iiwa, skew}}).find("robot 'a': "), std::string::npos);
}

}  // namespace
}  // namespace kinograph::dynamics

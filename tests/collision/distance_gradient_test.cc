// ∂d/∂q = nᵀ J_p(witness) against central differences of the signed distance, for robot
// versus obstacle pairs and self-collision pairs, separated and penetrating.
#include "kinograph/collision/distance_gradient.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "kinograph/collision/collision_world.h"
#include "kinograph/dynamics/kinematics.h"

namespace kinograph::collision {
namespace {

// Three revolute joints about z, y and x; spheres and a capsule as collision geometry.
const char* kArm = R"(<?xml version="1.0"?>
<robot name="grad_arm">
  <link name="base"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.3" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="2"/>
  </joint>
  <link name="l1">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><origin xyz="0.2 0 0.1" rpy="0 0 0"/><geometry><sphere radius="0.08"/></geometry></collision>
  </link>
  <joint name="j2" type="revolute">
    <parent link="l1"/><child link="l2"/>
    <origin xyz="0.3 0 0.1" rpy="0.2 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="2"/>
  </joint>
  <link name="l2">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><origin xyz="0.3 0.05 0" rpy="0 0 0"/><geometry><sphere radius="0.06"/></geometry></collision>
  </link>
  <joint name="j3" type="revolute">
    <parent link="l2"/><child link="l3"/>
    <origin xyz="0.4 0 0" rpy="0 0.3 0"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="2"/>
  </joint>
  <link name="l3">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><origin xyz="0.1 0.1 0.05" rpy="0 0 0"/><geometry><sphere radius="0.05"/></geometry></collision>
    <collision><origin xyz="0.15 -0.1 0" rpy="0 1.2 0.4"/><geometry><box size="0.1 0.05 0.2"/></geometry></collision>
  </link>
</robot>)";

Obstacle obstacle(int id, Shape shape, const Eigen::Vector3d& p, const Eigen::Quaterniond& r) {
  Obstacle o;
  o.id = id;
  o.shape = std::move(shape);
  o.pose.linear() = r.toRotationMatrix();
  o.pose.translation() = p;
  return o;
}

// The signed distance of the same pair as p, at configuration q.
double pair_distance_at(const dynamics::Model& model, dynamics::Data& data, CollisionWorld& world,
                        const Proximity& p, const Eigen::VectorXd& q) {
  dynamics::forward_kinematics(model, data, q);
  for (const Proximity& other : world.query(data, 0, INFINITY)) {
    if (other.robot_geom == p.robot_geom && other.obstacle == p.obstacle &&
        other.other_geom == p.other_geom) {
      return other.distance;
    }
  }
  ADD_FAILURE() << "pair disappeared";
  return NAN;
}

TEST(DistanceGradient, MatchesCentralDifferences) {
  const dynamics::Model model = dynamics::Model::from_urdf_string(kArm);
  ASSERT_EQ(model.nq(), 3);
  dynamics::Data data(model);
  CollisionWorldOptions opts;
  opts.self_collision = true;
  opts.cull = false;
  CollisionWorld world(model, opts);
  ASSERT_TRUE(world.add_obstacle(obstacle(1, Shape::box(0.3, 0.4, 0.2), {0.6, 0.4, 0.5},
                                          Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2).normalized())));
  ASSERT_TRUE(world.add_obstacle(
      obstacle(2, Shape::sphere(0.1), {0.5, -0.4, 0.2}, Eigen::Quaterniond::Identity())));
  ASSERT_TRUE(world.add_obstacle(obstacle(3, Shape::capsule(0.05, 0.4), {0.9, 0.0, 0.3},
                                          Eigen::Quaterniond(0.7, 0.7, 0, 0).normalized())));
  DistanceGradientWorkspace ws(model);
  Eigen::VectorXd grad(3);

  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  const double h = 1e-6;
  int checked = 0, penetrating = 0, self = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const Eigen::Vector3d q(u(rng), u(rng), u(rng));
    dynamics::forward_kinematics(model, data, q);
    const std::vector<Proximity> pairs(world.query(data, 0, INFINITY).begin(),
                                       world.query(data, 0, INFINITY).end());
    for (const Proximity& p : pairs) {
      dynamics::forward_kinematics(model, data, q);
      distance_gradient(model, data, p, ws, grad);
      Eigen::Vector3d fd;
      for (int j = 0; j < 3; ++j) {
        Eigen::VectorXd qp = q, qm = q;
        qp[j] += h;
        qm[j] -= h;
        fd[j] = (pair_distance_at(model, data, world, p, qp) -
                 pair_distance_at(model, data, world, p, qm)) /
                (2 * h);
      }
      SCOPED_TRACE(testing::Message()
                   << "trial " << trial << " geom " << p.robot_geom << " obstacle " << p.obstacle
                   << " other " << p.other_geom << " d " << p.distance);
      EXPECT_LT((grad - fd).norm(), 2e-5 * std::max(1.0, fd.norm()))
          << "analytic " << grad.transpose() << " fd " << fd.transpose();
      ++checked;
      penetrating += p.distance < 0;
      self += p.is_self_collision();
    }
  }
  EXPECT_GT(checked, 100);
  EXPECT_GT(self, 10);
  EXPECT_GT(penetrating, 0);  // the scene is tight enough to include penetration
}

}  // namespace
}  // namespace kinograph::collision

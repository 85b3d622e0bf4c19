#pragma once
// Robots, trajectories and plans for the renderer's tests (the planner does not exist yet, so
// plans are smooth joint-space interpolations).
#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "kinograph/dynamics/model.h"
#include "render/image.h"
#include "render/plan_json.h"
#include "render/render_scene.h"

namespace kinograph::render::test {

/// A 3-joint arm (base yaw about z, shoulder and elbow about y) with thick red cylinders on a
/// dark base, so its pixels are easy to tell from the floor, the sky and blue obstacles.
inline std::string red_arm_urdf() {
  return R"(<?xml version="1.0"?>
<robot name="red_arm">
  <material name="red"><color rgba="0.9 0.08 0.08 1"/></material>
  <material name="dark"><color rgba="0.2 0.2 0.2 1"/></material>
  <link name="base">
    <visual><origin xyz="0 0 0.05"/><geometry><box size="0.2 0.2 0.1"/></geometry>
      <material name="dark"/></visual>
  </link>
  <joint name="yaw" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="50" velocity="2"/>
  </joint>
  <link name="l1">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><origin xyz="0 0 0.2"/><geometry><cylinder radius="0.06" length="0.4"/></geometry>
      <material name="red"/></visual>
  </link>
  <joint name="shoulder" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0.4"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="50" velocity="2"/>
  </joint>
  <link name="l2">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><origin xyz="0 0 0.25"/><geometry><cylinder radius="0.05" length="0.5"/></geometry>
      <material name="red"/></visual>
  </link>
  <joint name="elbow" type="revolute"><parent link="l2"/><child link="l3"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="20" velocity="2"/>
  </joint>
  <link name="l3">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><origin xyz="0 0 0.2"/><geometry><cylinder radius="0.045" length="0.4"/></geometry>
      <material name="red"/></visual>
  </link>
  <joint name="tip_joint" type="fixed"><parent link="l3"/><child link="tip"/><origin xyz="0 0 0.45"/></joint>
  <link name="tip"/>
</robot>
)";
}

/// Minimum-jerk interpolation from q0 to q1 over `duration` seconds in `steps` + 1 samples.
inline Trajectory smooth_trajectory(const Eigen::VectorXd& q0, const Eigen::VectorXd& q1,
                                    double duration = 2.0, int steps = 20) {
  Trajectory trajectory;
  for (int k = 0; k <= steps; ++k) {
    const double s = double(k) / steps;
    const double h = s * s * s * (10 - 15 * s + 6 * s * s);
    trajectory.t.push_back(duration * s);
    trajectory.q.push_back(q0 + h * (q1 - q0));
  }
  return trajectory;
}

/// Whether the pixel's colour is clearly red (the arm), whatever the shading.
inline bool is_red(const std::uint8_t* p) { return p[0] > p[1] + 50 && p[0] > p[2] + 50; }
/// Whether the pixel's colour is clearly blue (obstacles by default).
inline bool is_blue(const std::uint8_t* p) { return p[2] > p[0] + 40 && p[2] > p[1] + 10; }

/// Counts pixels in a (2r+1)² window around (x, y) that satisfy `pred` (tolerates the
/// sub-pixel difference between our projection and the rasterizer's).
template <typename Pred>
int count_near(const Image& image, const Eigen::Vector2d& at, int r, Pred pred) {
  int count = 0;
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      const int x = static_cast<int>(std::floor(at.x())) + dx;
      const int y = static_cast<int>(std::floor(at.y())) + dy;
      if (x >= 0 && y >= 0 && x < image.width && y < image.height && pred(image.at(x, y))) {
        ++count;
      }
    }
  }
  return count;
}

/// A plan file for robots/iiwa14 (joint-space interpolation, made-up smooth torques).
inline PlanFile iiwa_test_plan(int steps = 25) {
  PlanFile plan;
  plan.urdf = "robots/iiwa14/iiwa14.urdf";
  for (int i = 1; i <= 7; ++i) plan.joint_names.push_back("iiwa_joint_" + std::to_string(i));
  Eigen::VectorXd q0(7), q1(7);
  q0 << 0.0, 0.3, 0.0, -1.2, 0.0, 0.8, 0.0;
  q1 << 1.8, -0.4, 0.3, -1.6, 0.2, 1.0, 0.5;
  const Trajectory tr = smooth_trajectory(q0, q1, 2.5, steps);
  plan.t = tr.t;
  plan.q = tr.q;
  for (double t : plan.t) {
    Eigen::VectorXd tau(7);
    for (int j = 0; j < 7; ++j) tau[j] = 30.0 * std::sin(2.5 * t + j);
    plan.tau.push_back(tau);
  }
  plan.effort_limits = {320, 320, 176, 176, 110, 40, 40};
  PlanObstacle desk;
  desk.id = "desk";
  desk.shape = "box";
  desk.size = {0.6, 0.8, 0.4};
  desk.position = Eigen::Vector3d(0.7, 0.5, 0.2);
  plan.obstacles.push_back(desk);
  return plan;
}

}  // namespace kinograph::render::test

#pragma once
// Robots, trajectories and plan files for the renderer's tests (plans are smooth joint-space
// interpolations, written by the planner's plan-file writer).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "kinograph/dynamics/model.h"
#include "kinograph/planning/io/plan_json.h"
#include "kinograph/planning/io/scene.h"
#include "render/image.h"
#include "render/render_scene.h"
#include "tests/lib/temp_dir.h"

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

/// The plan file (JSON, as the planner writes it) of robots/iiwa14 moving beside a desk
/// (joint-space interpolation; made-up smooth torques, zero qd and qdd).
inline nlohmann::json iiwa_test_plan(int steps = 25) {
  planning::Scene scene;
  scene.urdf_path = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/iiwa14/iiwa14.urdf";
  scene.problem.name = "iiwa test";
  scene.problem.model =
      std::make_shared<const dynamics::Model>(dynamics::Model::from_urdf_file(scene.urdf_path));
  collision::Obstacle desk;
  desk.shape = collision::Shape::box(0.6, 0.8, 0.4);
  desk.pose.translation() = Eigen::Vector3d(0.7, 0.5, 0.2);
  scene.problem.obstacles.push_back(desk);
  scene.obstacle_names.push_back("desk");
  Eigen::VectorXd q0(7), q1(7);
  q0 << 0.0, 0.3, 0.0, -1.2, 0.0, 0.8, 0.0;
  q1 << 1.8, -0.4, 0.3, -1.6, 0.2, 1.0, 0.5;
  const Trajectory tr = smooth_trajectory(q0, q1, 2.5, steps);
  planning::Plan plan;
  plan.t = tr.t;
  const int rows = static_cast<int>(tr.t.size());
  plan.q.resize(rows, 7);
  plan.tau.resize(rows, 7);
  plan.qd = plan.qdd = Eigen::MatrixXd::Zero(rows, 7);
  for (int k = 0; k < rows; ++k) {
    plan.q.row(k) = tr.q[k].transpose();
    for (int j = 0; j < 7; ++j) plan.tau(k, j) = 30.0 * std::sin(2.5 * tr.t[k] + j);
  }
  return planning::plan_to_json(plan, scene);
}

/// A fresh temporary folder for the running test, named after it and made unique: ctest -j runs
/// the tests of one fixture in parallel processes, which must not share (and remove) each
/// other's files. The caller removes it.
inline std::filesystem::path make_test_dir(const std::string& prefix) {
  return test_support::TempDir::make(
      prefix + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
}

/// Writes a plan file's JSON to `path`.
inline void write_json(const nlohmann::json& json, const std::string& path) {
  std::ofstream(path) << json.dump(1) << "\n";
}

}  // namespace kinograph::render::test

#pragma once
// Shared fixtures of the dynamics tests: robot paths, a branching test tree, seeded states.
#include <Eigen/Core>
#include <random>
#include <string>

#include "kinograph/dynamics/model.h"

namespace kinograph::dynamics::testing {

inline std::string robot_path(const std::string& rel) {
  return std::string(KINOGRAPH_SOURCE_DIR) + "/robots/" + rel;
}
inline std::string data_path(const std::string& rel) {
  return std::string(KINOGRAPH_SOURCE_DIR) + "/tests/dynamics/data/" + rel;
}

// A branching tree with every supported joint kind (revolute, continuous, prismatic, fixed
// joints to merge, a massless fixed leaf), tilted origins and inertials with off-diagonal
// terms, so no term of the algorithms hides behind a zero. Bodies: a, b, c, d, e, f.
inline const char* kTreeUrdf = R"(<?xml version="1.0"?>
<robot name="tree">
  <link name="base"/>
  <joint name="ja" type="revolute">
    <parent link="base"/><child link="a"/>
    <origin xyz="0.1 -0.05 0.3" rpy="0.2 -0.1 0.4"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="50" velocity="3"/><dynamics damping="0.3"/>
  </joint>
  <link name="a">
    <inertial><origin xyz="0.02 0.01 0.15" rpy="0.3 0.1 -0.2"/><mass value="3.0"/>
      <inertia ixx="0.05" ixy="0.002" ixz="-0.001" iyy="0.04" iyz="0.003" izz="0.02"/></inertial>
  </link>
  <joint name="jb" type="revolute">
    <parent link="a"/><child link="b"/>
    <origin xyz="0 0.1 0.3" rpy="1.2 0.3 -0.5"/><axis xyz="1 1 0"/>
    <limit lower="-2" upper="2" effort="40" velocity="3"/>
  </joint>
  <link name="b">
    <inertial><origin xyz="0.2 -0.03 0.05" rpy="-0.4 0.2 0.1"/><mass value="2.0"/>
      <inertia ixx="0.01" ixy="0.001" ixz="0.0005" iyy="0.03" iyz="-0.002" izz="0.025"/></inertial>
  </link>
  <joint name="jc" type="prismatic">
    <parent link="a"/><child link="c"/>
    <origin xyz="0.05 -0.2 0.25" rpy="0 0.7 0.2"/><axis xyz="1 0 0.5"/>
    <limit lower="-0.5" upper="0.5" effort="100" velocity="1"/><dynamics damping="2.0"/>
  </joint>
  <link name="c">
    <inertial><origin xyz="0.1 0.02 -0.04" rpy="0 0 0.3"/><mass value="1.5"/>
      <inertia ixx="0.02" ixy="0" ixz="0.001" iyy="0.015" iyz="0" izz="0.01"/></inertial>
  </link>
  <joint name="jc_fixed" type="fixed">
    <parent link="c"/><child link="c_ext"/><origin xyz="0.2 0 0.1" rpy="0.5 -0.3 0.9"/>
  </joint>
  <link name="c_ext">
    <inertial><origin xyz="0.03 0.02 0.01" rpy="0.1 0.2 0.3"/><mass value="0.7"/>
      <inertia ixx="0.003" ixy="0.0002" ixz="0" iyy="0.004" iyz="0.0001" izz="0.002"/></inertial>
  </link>
  <joint name="jd" type="continuous">
    <parent link="c_ext"/><child link="d"/>
    <origin xyz="0 0.1 0.05" rpy="-0.6 0.1 0.2"/><axis xyz="0 1 1"/><dynamics damping="0.05"/>
  </joint>
  <link name="d">
    <inertial><origin xyz="0.05 0.05 0.1" rpy="0 0 0"/><mass value="1.0"/>
      <inertia ixx="0.004" ixy="0" ixz="0" iyy="0.005" iyz="0" izz="0.006"/></inertial>
  </link>
  <joint name="je" type="revolute">
    <parent link="b"/><child link="e"/>
    <origin xyz="0.3 0 0" rpy="0 -0.4 0"/><axis xyz="0 0 -1"/>
    <limit lower="-3" upper="3" effort="10" velocity="4"/>
  </joint>
  <link name="e">
    <inertial><origin xyz="0 0 0.1" rpy="0 0 0"/><mass value="0.8"/>
      <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.001"/></inertial>
  </link>
  <joint name="e_tool" type="fixed">
    <parent link="e"/><child link="e_tool_frame"/><origin xyz="0 0.05 0.2" rpy="0.1 0 0"/>
  </joint>
  <link name="e_tool_frame"/>
  <joint name="jf" type="prismatic">
    <parent link="e_tool_frame"/><child link="f"/>
    <origin xyz="0 0 0.05" rpy="0.3 0.3 0.3"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0.2" effort="20" velocity="0.5"/>
  </joint>
  <link name="f">
    <inertial><origin xyz="0.01 0 0.02" rpy="0 0 0"/><mass value="0.3"/>
      <inertia ixx="0.0005" ixy="0" ixz="0" iyy="0.0005" iyz="0" izz="0.0003"/></inertial>
  </link>
</robot>
)";

// Seeded uniform vector in [-scale, scale]^n.
inline Eigen::VectorXd random_vector(std::mt19937& rng, int n, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

}  // namespace kinograph::dynamics::testing

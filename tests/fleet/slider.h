#pragma once
// Test robots with closed-form distances: one prismatic joint along x carrying a sphere, placed
// anywhere, and constant-velocity plans (exact on the cubic interpolant: q̈ = 0).
#include <Eigen/Geometry>
#include <memory>
#include <string>

#include <sstream>
#include "kinograph/dynamics/model.h"
#include "kinograph/planning/plan.h"

namespace kinograph::fleet::testing {

inline constexpr double kSphereRadius = 0.1;

// A robot whose link 'ball' (a 0.1 m sphere) slides along the world x axis from `base` (the
// joint's origin: where a robot standing at `base` would have it).
inline std::shared_ptr<const dynamics::Model> slider(const Eigen::Vector3d& base) {
  std::ostringstream origin;
  origin << "<origin xyz=\"" << base.x() << " " << base.y() << " " << base.z() << "\"/>";
  const std::string urdf = R"(<robot name="slider">
  <link name="rail"/>
  <link name="ball">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><sphere radius="0.1"/></geometry></collision>
  </link>
  <joint name="slide" type="prismatic">
    <parent link="rail"/><child link="ball"/><axis xyz="1 0 0"/>)" + origin.str() + R"(
    <limit lower="-10" upper="10" velocity="10" effort="100"/>
  </joint>
</robot>)";
  return std::make_shared<const dynamics::Model>(dynamics::Model::from_urdf_string(urdf));
}

// q = q0 + v t at `knots` + 1 evenly spaced knots over [0, duration].
inline planning::Plan constant_velocity(double q0, double v, double duration, int knots) {
  planning::Plan p;
  p.q.resize(knots + 1, 1);
  p.qd = Eigen::MatrixXd::Constant(knots + 1, 1, v);
  p.qdd = Eigen::MatrixXd::Zero(knots + 1, 1);
  p.tau = Eigen::MatrixXd::Zero(knots + 1, 1);
  for (int k = 0; k <= knots; ++k) {
    p.t.push_back(duration * k / knots);
    p.q(k, 0) = q0 + v * p.t.back();
  }
  return p;
}

}  // namespace kinograph::fleet::testing

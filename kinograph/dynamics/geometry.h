#pragma once
// A collision or visual shape attached to one body of a robot Model.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

namespace kinograph::dynamics {

/// One collision or visual shape from the URDF (or added by a payload), posed in its body.
struct Geometry {
  enum class Shape { kSphere, kBox, kCylinder, kCapsule, kMesh };
  Shape shape = Shape::kSphere;
  /// Sphere (radius, 0, 0); box full extents (x, y, z); cylinder and capsule (radius, length, 0)
  /// along the local z axis, the capsule's length measured between its cap centres.
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  /// Absolute path of the mesh file after resolving package:// and relative paths.
  std::string mesh_path;
  Eigen::Vector3d mesh_scale = Eigen::Vector3d::Ones();
  /// Pose of the shape in the owning body's frame (or in the base frame when body == -1).
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
  /// Colour from the URDF material; a default grey when the URDF gives none.
  Eigen::Vector4d rgba{0.7, 0.7, 0.7, 1.0};
  /// Index into Model::bodies; -1 means the fixed base (the URDF root link).
  int body = -1;
  /// URDF link the shape came from (after fixed-joint merging this may differ from the body).
  std::string link_name;
};

}  // namespace kinograph::dynamics

#include "render/camera.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace kinograph::render {

namespace {

// Orthonormal camera basis: x right, y up, z from target to eye (so the camera looks down −z).
Eigen::Matrix3d basis(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                      const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = (eye - target).normalized();
  Eigen::Vector3d x = up.cross(z);
  if (x.norm() < 1e-9) x = Eigen::Vector3d::UnitX().cross(z);  // looking along up
  if (x.norm() < 1e-9) x = Eigen::Vector3d::UnitY().cross(z);
  x.normalize();
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  return r;
}

}  // namespace

Eigen::Matrix4d Camera::view() const {
  const Eigen::Matrix3d r = basis(eye, target, up);
  Eigen::Matrix4d v = Eigen::Matrix4d::Identity();
  v.topLeftCorner<3, 3>() = r.transpose();
  v.topRightCorner<3, 1>() = -r.transpose() * eye;
  return v;
}

Eigen::Matrix4d Camera::projection(double aspect) const {
  const double f = 1.0 / std::tan(0.5 * fov_y_deg * std::numbers::pi / 180.0);
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = f / aspect;
  p(1, 1) = f;
  p(2, 2) = (far + near) / (near - far);
  p(2, 3) = 2.0 * far * near / (near - far);
  p(3, 2) = -1.0;
  return p;
}

std::optional<Eigen::Vector2d> Camera::project(const Eigen::Vector3d& point, int width,
                                               int height) const {
  const Eigen::Vector4d clip = projection(double(width) / height) * view() * point.homogeneous();
  if (clip.w() <= 0) return std::nullopt;
  const double ndc_x = clip.x() / clip.w(), ndc_y = clip.y() / clip.w();
  return Eigen::Vector2d(0.5 * (ndc_x + 1.0) * width, 0.5 * (1.0 - ndc_y) * height);
}

Camera frame_bounds(const Eigen::AlignedBox3d& bounds, const Eigen::Vector3d& view_dir,
                    double aspect, const Eigen::Vector3d& up, double fov_y_deg, double margin) {
  Camera camera;
  camera.up = up;
  camera.fov_y_deg = fov_y_deg;
  const Eigen::Vector3d center = bounds.center();
  const Eigen::Matrix3d r = basis(center + view_dir, center, up);
  const double tan_v = std::tan(0.5 * fov_y_deg * std::numbers::pi / 180.0) * (1.0 - 2 * margin);
  const double tan_h = tan_v * aspect;
  // Smallest distance d along view_dir at which every corner lies inside the frustum:
  // a corner at lateral offsets (x, y) and depth offset z (towards the eye) needs
  // |x| <= (d − z)·tan_h and |y| <= (d − z)·tan_v.
  double distance = 0.0, depth = 0.0;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d c =
        r.transpose() * (bounds.corner(static_cast<Eigen::AlignedBox3d::CornerType>(i)) - center);
    distance =
        std::max({distance, std::abs(c.x()) / tan_h + c.z(), std::abs(c.y()) / tan_v + c.z()});
    depth = std::max(depth, std::abs(c.z()));
  }
  distance = std::max(distance, 1e-3);
  camera.target = center;
  camera.eye = center + distance * r.col(2);
  const double radius = 0.5 * bounds.diagonal().norm();
  camera.near = std::max(1e-3, 0.5 * (distance - depth));
  camera.far = distance + 4.0 * radius + 10.0;  // room for the floor beyond the motion
  return camera;
}

}  // namespace kinograph::render

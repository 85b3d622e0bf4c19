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

Camera frame_points(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& view_dir,
                    double aspect, const Eigen::Vector3d& up, double fov_y_deg, double margin) {
  Eigen::AlignedBox3d bounds;
  for (const Eigen::Vector3d& p : points) bounds.extend(p);
  if (bounds.isEmpty()) bounds.extend(Eigen::Vector3d::Zero());
  Camera camera;
  camera.up = up;
  camera.fov_y_deg = fov_y_deg;
  const Eigen::Matrix3d r = basis(bounds.center() + view_dir, bounds.center(), up);
  const double tan_v = std::tan(0.5 * fov_y_deg * std::numbers::pi / 180.0) * (1.0 - 2 * margin);
  const double tan_h = tan_v * aspect;
  // Points in camera axes relative to the target; the eye sits at distance d along +z. A point
  // (x, y, z) projects to x / ((d − z) tan_h). Alternate: fit d for the current target, then
  // move the target sideways to centre the projected extents (converges in a few rounds).
  Eigen::Vector3d target = bounds.center();
  double distance = 1.0;
  for (int round = 0; round < 4; ++round) {
    distance = 1e-3;
    for (const Eigen::Vector3d& p : points) {
      const Eigen::Vector3d c = r.transpose() * (p - target);
      distance =
          std::max({distance, std::abs(c.x()) / tan_h + c.z(), std::abs(c.y()) / tan_v + c.z()});
    }
    double lo_x = 1e300, hi_x = -1e300, lo_y = 1e300, hi_y = -1e300;
    for (const Eigen::Vector3d& p : points) {
      const Eigen::Vector3d c = r.transpose() * (p - target);
      const double depth = std::max(distance - c.z(), 1e-6);
      lo_x = std::min(lo_x, c.x() / depth);
      hi_x = std::max(hi_x, c.x() / depth);
      lo_y = std::min(lo_y, c.y() / depth);
      hi_y = std::max(hi_y, c.y() / depth);
    }
    target += r.col(0) * 0.5 * (lo_x + hi_x) * distance + r.col(1) * 0.5 * (lo_y + hi_y) * distance;
  }
  distance = 1e-3;
  double near_depth = 1e300, far_depth = 0.0;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d c = r.transpose() * (p - target);
    distance =
        std::max({distance, std::abs(c.x()) / tan_h + c.z(), std::abs(c.y()) / tan_v + c.z()});
  }
  for (const Eigen::Vector3d& p : points) {
    const double depth = distance - (r.transpose() * (p - target)).z();
    near_depth = std::min(near_depth, depth);
    far_depth = std::max(far_depth, depth);
  }
  camera.target = target;
  camera.eye = target + distance * r.col(2);
  camera.near = std::max(1e-3, 0.5 * near_depth);
  camera.far = far_depth + 2.0 * bounds.diagonal().norm() + 10.0;  // room for the floor
  return camera;
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

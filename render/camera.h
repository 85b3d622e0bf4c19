#pragma once
// A pinhole camera and the automatic framing that shows a whole motion.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <vector>

namespace kinograph::render {

/// Perspective camera looking from `eye` at `target`; `up` fixes the roll.
struct Camera {
  Eigen::Vector3d eye = Eigen::Vector3d(3, -3, 2);
  Eigen::Vector3d target = Eigen::Vector3d(0, 0, 0.5);
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  double fov_y_deg = 30.0;  ///< vertical field of view
  double near = 0.05;       ///< clip distances in metres; auto framing sets them from the bounds
  double far = 50.0;

  /// World → camera (OpenGL convention: camera looks down its −z).
  Eigen::Matrix4d view() const;
  /// Camera → clip for a viewport of the given width/height ratio.
  Eigen::Matrix4d projection(double aspect) const;
  /// Pixel coordinates (x right, y down, origin at the top-left corner of the viewport) of a
  /// world point in a width × height viewport; nullopt if it is behind the camera.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& point, int width, int height) const;
};

/// Camera that sees all of `bounds` from direction `view_dir` (from the target towards the
/// eye) with `margin` (fraction of the frame) to spare, in a viewport of ratio `aspect`.
Camera frame_bounds(const Eigen::AlignedBox3d& bounds, const Eigen::Vector3d& view_dir,
                    double aspect, const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ(),
                    double fov_y_deg = 30.0, double margin = 0.08);

/// Camera that sees every point of `points` from direction `view_dir`, with the points'
/// projection centred in the frame (tighter than framing their bounding box).
Camera frame_points(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& view_dir,
                    double aspect, const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ(),
                    double fov_y_deg = 30.0, double margin = 0.06);

}  // namespace kinograph::render

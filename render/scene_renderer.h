#pragma once
// Pictures of plans: frame strips (the robot at evenly spaced times, side by side, as the
// paper's figures) and ghost overlays (all frames in one view, fading from start to goal).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "kinograph/dynamics/data.h"
#include "render/camera.h"
#include "render/image.h"
#include "render/render_scene.h"
#include "render/renderer.h"

namespace kinograph::render {

/// How a plan is drawn; defaults give the 5-frame 1600×400 strip of the issue.
struct FrameOptions {
  int frames = 5;    ///< robot poses drawn, evenly spaced in time (must be ≥ 1)
  int width = 1600;  ///< whole picture, pixels
  int height = 400;
  bool labels = true;  ///< "t = 1.25 s" over each strip panel / a caption over a ghost overlay
  bool floor = true;   ///< checker floor (3-D robots) or backdrop (planar robots)
  float ghost_min_alpha = 0.18f;  ///< opacity of the first ghost; the last pose is opaque
  Eigen::Vector4f background = Eigen::Vector4f(1.f, 1.f, 1.f, 1.f);
  Eigen::Vector4f path_color = Eigen::Vector4f(0.85f, 0.12f, 0.08f, 1.f);  ///< end-effector path
};

/// One view in a picture: its pixel rectangle (top-left origin) and the camera that drew it,
/// so callers (and tests) can project world points into the picture.
struct Panel {
  int x = 0, y = 0, width = 0, height = 0;
  Camera camera;
  double time = 0.0;  ///< the pose's time (strip panels); the last time for a ghost overlay

  /// Pixel of a world point in the whole picture, nullopt if behind the camera.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& p) const;
};

/// A rendered picture with the panels it is made of and the times of the poses drawn.
struct RenderResult {
  Image image;
  std::vector<Panel> panels;
  std::vector<double> times;
};

/// Draws plans with one GL context; meshes are loaded and uploaded once and reused across
/// pictures, so a daemon or a benchmark keeps one SceneRenderer alive.
class SceneRenderer {
 public:
  explicit SceneRenderer(const RendererOptions& options = {});

  /// N frames side by side, each labelled with its time. Throws std::invalid_argument for an
  /// invalid scene or options, std::runtime_error for an unreadable mesh (naming the file).
  RenderResult strip(const RenderScene& scene, const FrameOptions& options = {});
  /// All N frames in one view with opacity rising from start to goal and the end-effector
  /// path drawn as a tube. Throws as strip() does.
  RenderResult ghost(const RenderScene& scene, const FrameOptions& options = {});

  /// Corners of every shape's box over the trajectory (60 samples at most) and of the
  /// obstacles: the points a camera must see.
  std::vector<Eigen::Vector3d> motion_points(const RenderScene& scene);
  /// World bounds of motion_points (at least 0.1 m on a side).
  Eigen::AlignedBox3d motion_bounds(const RenderScene& scene);
  /// Camera framing motion_points for a viewport of ratio `aspect`: along the joint axis for
  /// planar robots, from the front-right and above otherwise.
  Camera auto_camera(const RenderScene& scene, double aspect);

  /// The underlying GL renderer.
  Renderer& renderer() { return renderer_; }

 private:
  struct Floor {
    MeshId mesh = -1;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  };
  MeshId geometry_mesh(const dynamics::Geometry& geometry);
  void robot_items(const dynamics::Model& model, dynamics::Data& data, const Eigen::VectorXd& q,
                   std::vector<DrawItem>& items);
  std::vector<DrawItem> obstacle_items(const RenderScene& scene);
  Floor make_floor(const RenderScene& scene, const Camera& camera);
  static void check_options(const FrameOptions& options);

  Renderer renderer_;
};

}  // namespace kinograph::render

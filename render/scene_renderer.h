#pragma once
// Pictures of plans: frame strips (the robot at evenly spaced times, side by side, as the
// paper's figures), ghost overlays (all frames in one view, fading from start to goal) and two
// plans compared in one view (the replanning figure). Moving obstacles are drawn where they are
// at each pose's time.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "kinograph/dynamics/data.h"
#include "render/camera.h"
#include "render/image.h"
#include "render/render_scene.h"
#include "render/renderer.h"

namespace kinograph::render {

/// How a plan is drawn; defaults give a 5-frame 1600×400 strip.
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

/// How two plans of one task are drawn in one view (the replanning figure): the first plan's
/// poses as grey ghosts with their end-effector path, the second in the robot's colours as a
/// ghost overlay with its own path, among the second plan's obstacles.
struct CompareOptions {
  FrameOptions frame;  ///< poses per plan, size, labels, floor; frame.path_color: second plan
  Eigen::Vector4f before_color = Eigen::Vector4f(0.55f, 0.57f, 0.60f, 1.f);  ///< first's tint
  float before_min_alpha = 0.15f;  ///< opacity of the first plan's first pose
  float before_max_alpha = 0.45f;  ///< and of its last pose (all of its poses are ghosts)
  Eigen::Vector4f before_path_color = Eigen::Vector4f(0.10f, 0.62f, 0.25f, 1.f);
  /// Colour of the second plan's obstacles that the first plan did not have as they are (see
  /// highlight_changed_obstacles); nullopt keeps their own colours.
  std::optional<Eigen::Vector4d> changed_color = Eigen::Vector4d(0.85, 0.25, 0.65, 1.0);
  std::string before_label = "before";  ///< legend lines (frame.labels), in the paths' colours
  std::string after_label = "after";
  std::string changed_label = "changed obstacles";  ///< shown when some obstacle changed
  /// Shown when the first plan has obstacles (by name) the second has not; they are drawn
  /// faded, as the first plan's poses.
  std::string removed_label = "removed obstacles (faded)";
  /// With a fixed camera (a scene's), keep its direction, up and field of view but move it
  /// to frame both motions: a scene's camera is set up for strip panels, not for this view.
  bool reframe_camera = true;
  double path_radius = 0.005;  ///< of both path tubes, as a fraction of the view's diagonal
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

  /// Two plans in one view (see CompareOptions), framed so both motions show; `after`'s
  /// camera, when set, is used. Throws as strip() does, or when the plans' robots differ in
  /// joint count.
  RenderResult compare(const RenderScene& before, const RenderScene& after,
                       const CompareOptions& options = {});

  /// Corners of every shape's box over the trajectory (60 samples at most) and of the
  /// obstacles: the points a camera must see.
  std::vector<Eigen::Vector3d> motion_points(const RenderScene& scene);
  /// World bounds of motion_points (at least 0.1 m on a side).
  Eigen::AlignedBox3d motion_bounds(const RenderScene& scene);
  /// Camera framing motion_points for a viewport of ratio `aspect`: along the joint axis for
  /// planar robots, from the front-right and above otherwise (the scene's camera when set).
  Camera auto_camera(const RenderScene& scene, double aspect);

  /// The underlying GL renderer.
  Renderer& renderer() { return renderer_; }

 private:
  struct Floor {
    MeshId mesh = -1;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  };
  // One plan's part of an overlay view: its poses as ghosts with opacity rising from
  // min_alpha to max_alpha (a pose at opacity 1 is drawn solid), its end-effector path.
  struct Layer {
    const RenderScene* scene = nullptr;
    std::optional<Eigen::Vector4f> tint;  // one colour for the whole robot
    float min_alpha = 0.18f, max_alpha = 1.f;
    bool obstacles = true;  // draw this plan's obstacles
    Eigen::Vector4f path_color;
    std::string path_key;              // mesh key of its path tube (one per layer of a picture)
    double path_radius = 0.0035;       // of the tube, as a fraction of the view's bounds' diagonal
    std::vector<SceneObstacle> faded;  // obstacles drawn as ghosts at the layer's first opacity
  };
  RenderResult overlay(const std::vector<Layer>& layers, const Camera& camera,
                       const std::vector<Eigen::Vector3d>& points, const FrameOptions& options);
  Camera camera_for(const RenderScene& scene, const std::vector<Eigen::Vector3d>& points,
                    double aspect);
  MeshId geometry_mesh(const dynamics::Geometry& geometry);
  MeshId obstacle_mesh(const collision::Shape& shape);
  void robot_items(const dynamics::Model& model, dynamics::Data& data, const Eigen::VectorXd& q,
                   std::vector<DrawItem>& items);
  // Appends the obstacles where they are at `time`; `moving_only` leaves out fixed ones.
  void obstacle_items(const RenderScene& scene, double time, bool moving_only,
                      std::vector<DrawItem>& items);
  Floor make_floor(const Eigen::AlignedBox3d& bounds, const Camera& camera);
  static void check_options(const FrameOptions& options);

  Renderer renderer_;
};

}  // namespace kinograph::render

#include "render/scene_renderer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "kinograph/dynamics/kinematics.h"
#include "render/label.h"

namespace kinograph::render {

namespace {

using dynamics::Geometry;

Eigen::Isometry3d geometry_pose(const Geometry& g, const dynamics::Data& data) {
  return g.body < 0 ? g.origin : data.body_pose[g.body] * g.origin;
}

// A round cell size near extent / 8 (1, 2 or 5 times a power of ten) for the checker floor.
double nice_cell(double extent) {
  const double raw = std::max(extent / 8.0, 1e-3);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0}) {
    if (m * p >= raw) return m * p;
  }
  return 10.0 * p;
}

std::vector<Eigen::Vector3d> path_points(const RenderScene& scene, int frame) {
  const dynamics::Model& model = *scene.model;
  dynamics::Data data(model);
  const int count = std::clamp(static_cast<int>(scene.trajectory.t.size()) * 4, 100, 400);
  std::vector<Eigen::Vector3d> points;
  for (double t : scene.trajectory.even_times(count)) {
    dynamics::forward_kinematics(model, data, scene.trajectory.at(t));
    points.push_back(dynamics::frame_pose(model, data, frame).translation());
  }
  return points;
}

}  // namespace

std::optional<Eigen::Vector2d> Panel::project(const Eigen::Vector3d& p) const {
  auto pixel = camera.project(p, width, height);
  if (pixel) *pixel += Eigen::Vector2d(x, y);
  return pixel;
}

SceneRenderer::SceneRenderer(const RendererOptions& options) : renderer_(options) {}

void SceneRenderer::check_options(const FrameOptions& options) {
  if (options.frames < 1) {
    throw std::invalid_argument(
        fmt::format("render: the number of frames must be at least 1, got {}", options.frames));
  }
  if (options.width < 1 || options.height < 1) {
    throw std::invalid_argument(fmt::format("render: image size must be positive, got {}x{}",
                                            options.width, options.height));
  }
}

MeshId SceneRenderer::geometry_mesh(const Geometry& g) {
  const Eigen::Vector3d& s = g.size;
  switch (g.shape) {
    case Geometry::Shape::kSphere:
      return renderer_.mesh(fmt::format("sphere:{}", s.x()), [&] { return make_sphere(s.x()); });
    case Geometry::Shape::kBox:
      return renderer_.mesh(fmt::format("box:{}:{}:{}", s.x(), s.y(), s.z()),
                            [&] { return make_box(s); });
    case Geometry::Shape::kCylinder:
      return renderer_.mesh(fmt::format("cylinder:{}:{}", s.x(), s.y()),
                            [&] { return make_cylinder(s.x(), s.y()); });
    case Geometry::Shape::kCapsule:
      return renderer_.mesh(fmt::format("capsule:{}:{}", s.x(), s.y()),
                            [&] { return make_capsule(s.x(), s.y()); });
    case Geometry::Shape::kMesh:
      if (g.mesh_path.empty()) {
        throw std::runtime_error(
            fmt::format("render: mesh geometry of '{}' has no file name", g.link_name));
      }
      return renderer_.mesh(fmt::format("mesh:{}:{}:{}:{}", g.mesh_path, g.mesh_scale.x(),
                                        g.mesh_scale.y(), g.mesh_scale.z()),
                            [&] { return load_mesh(g.mesh_path, g.mesh_scale); });
  }
  throw std::invalid_argument("render: unknown geometry shape");
}

void SceneRenderer::robot_items(const dynamics::Model& model, dynamics::Data& data,
                                const Eigen::VectorXd& q, std::vector<DrawItem>& items) {
  dynamics::forward_kinematics(model, data, q);
  for (const Geometry& g : model.visual) {
    DrawItem item;
    item.mesh = geometry_mesh(g);
    item.pose = geometry_pose(g, data);
    item.color = g.rgba.cast<float>();
    items.push_back(item);
  }
}

std::vector<DrawItem> SceneRenderer::obstacle_items(const RenderScene& scene) {
  std::vector<DrawItem> items;
  for (const Geometry& g : scene.obstacles) {
    DrawItem item;
    item.mesh = geometry_mesh(g);
    item.pose = g.origin;
    item.color = g.rgba.cast<float>();
    items.push_back(item);
  }
  return items;
}

std::vector<Eigen::Vector3d> SceneRenderer::motion_points(const RenderScene& scene) {
  scene.check();
  const dynamics::Model& model = *scene.model;
  dynamics::Data data(model);
  std::vector<Eigen::Vector3d> points;
  const auto add_box = [&](const Eigen::AlignedBox3d& box, const Eigen::Isometry3d& pose) {
    if (box.isEmpty()) return;
    for (int i = 0; i < 8; ++i) {
      points.push_back(pose * box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(i)));
    }
  };
  const int samples = std::min<int>(static_cast<int>(scene.trajectory.t.size()), 60);
  for (double t : scene.trajectory.even_times(samples)) {
    dynamics::forward_kinematics(model, data, scene.trajectory.at(t));
    for (const Geometry& g : model.visual) {
      add_box(renderer_.mesh_bounds(geometry_mesh(g)), geometry_pose(g, data));
    }
    for (const Eigen::Isometry3d& pose : data.body_pose) points.push_back(pose.translation());
  }
  for (const Geometry& g : scene.obstacles)
    add_box(renderer_.mesh_bounds(geometry_mesh(g)), g.origin);
  if (points.empty()) points.push_back(Eigen::Vector3d::Zero());
  return points;
}

Eigen::AlignedBox3d SceneRenderer::motion_bounds(const RenderScene& scene) {
  Eigen::AlignedBox3d bounds;
  for (const Eigen::Vector3d& p : motion_points(scene)) bounds.extend(p);
  // A robot with no visual geometry (or a point) still gets a finite frame.
  const Eigen::Vector3d pad = (Eigen::Vector3d::Constant(0.1) - bounds.sizes()).cwiseMax(0.0) / 2;
  bounds.min() -= pad;
  bounds.max() += pad;
  return bounds;
}

Camera SceneRenderer::auto_camera(const RenderScene& scene, double aspect) {
  if (scene.camera) return *scene.camera;
  Eigen::Vector3d view_dir(1.0, -1.25, 0.7);  // front-right, above: shows depth of 3-D arms
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  if (auto axis = planar_axis(*scene.model, scene.trajectory.q.front())) {
    Eigen::Vector3d a = *axis;
    Eigen::Index dominant = 0;
    a.cwiseAbs().maxCoeff(&dominant);
    if (a[dominant] < 0) a = -a;
    if (dominant == 2) {  // motion in a horizontal plane: look down
      view_dir = Eigen::Vector3d::UnitZ();
      up = Eigen::Vector3d::UnitY();
    } else {
      view_dir = -a;
    }
  }
  return frame_points(motion_points(scene), view_dir.normalized(), aspect, up);
}

SceneRenderer::Floor SceneRenderer::make_floor(const RenderScene& scene, const Camera& camera) {
  const Eigen::AlignedBox3d bounds = motion_bounds(scene);
  const double extent = bounds.sizes().maxCoeff();
  const double cell = nice_cell(extent);
  const int cells = 2 * static_cast<int>(std::ceil(2.5 * extent / cell / 2.0)) + 8;
  const Eigen::Vector3d view_dir = (camera.eye - camera.target).normalized();
  const bool backdrop = std::abs(view_dir.z()) < 0.2;
  // A backdrop faces the camera and would dominate the picture at full contrast.
  const Eigen::Vector4f light(0.96f, 0.96f, 0.96f, 1.f);
  const Eigen::Vector4f dark = backdrop ? Eigen::Vector4f(0.89f, 0.90f, 0.92f, 1.f)
                                        : Eigen::Vector4f(0.80f, 0.81f, 0.84f, 1.f);
  Floor floor;
  floor.mesh = renderer_.mesh(fmt::format("checker:{}:{}:{}", cells, cell, backdrop),
                              [&] { return make_checker(cells, cell, light, dark); });
  const auto snap = [&](double v) { return 2.0 * cell * std::round(v / (2.0 * cell)); };
  if (backdrop) {
    // Seen from the side (planar robots): a backdrop behind the motion instead of a floor
    // that would show edge-on.
    const Eigen::Vector3d c = bounds.center();
    const double depth = std::abs((bounds.max() - bounds.min()).dot(view_dir)) / 2;
    floor.pose.linear() =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), view_dir).toRotationMatrix();
    floor.pose.translation() = c - (depth + 0.05 * extent + 0.02) * view_dir;
  } else {
    const double z = std::min(0.0, bounds.min().z());
    floor.pose.translation() =
        Eigen::Vector3d(snap(bounds.center().x()), snap(bounds.center().y()), z - 1e-3);
  }
  return floor;
}

RenderResult SceneRenderer::strip(const RenderScene& scene, const FrameOptions& options) {
  check_options(options);
  scene.check();
  RenderResult result;
  result.times = scene.trajectory.even_times(options.frames);
  const int n = options.frames;
  const int panel_w = options.width / n;
  if (panel_w < 1) {
    throw std::invalid_argument(
        fmt::format("render: {} frames do not fit in {} pixels", n, options.width));
  }
  const Camera camera = auto_camera(scene, double(panel_w) / options.height);
  std::vector<DrawItem> fixed;
  if (options.floor) {
    const Floor floor = make_floor(scene, camera);
    DrawItem item;
    item.mesh = floor.mesh;
    item.pose = floor.pose;
    fixed.push_back(item);
  }
  for (const DrawItem& item : obstacle_items(scene)) fixed.push_back(item);

  const dynamics::Model& model = *scene.model;
  dynamics::Data data(model);
  renderer_.begin(options.width, options.height, options.background);
  std::vector<DrawItem> items;
  for (int i = 0; i < n; ++i) {
    Panel panel;
    panel.x = options.width * i / n;
    panel.width = options.width * (i + 1) / n - panel.x;
    panel.height = options.height;
    panel.camera = camera;
    panel.time = result.times[i];
    renderer_.set_panel(panel.x, panel.y, panel.width, panel.height, camera);
    items = fixed;
    robot_items(model, data, scene.trajectory.at(panel.time), items);
    renderer_.draw(items);
    result.panels.push_back(panel);
  }
  result.image = renderer_.finish();
  for (std::size_t i = 1; i < result.panels.size(); ++i) {  // thin separators between panels
    for (int y = 0; y < options.height; ++y) {
      std::uint8_t* p = result.image.at(result.panels[i].x, y);
      p[0] = p[1] = p[2] = 150;
    }
  }
  if (options.labels) {
    const double size = std::clamp(options.height * 0.05, 11.0, 28.0);
    for (const Panel& panel : result.panels) {
      draw_label(result.image, fmt::format("t = {:.2f} s", panel.time), panel.x + 0.5 * panel.width,
                 0.3 * size, size);
    }
  }
  return result;
}

RenderResult SceneRenderer::ghost(const RenderScene& scene, const FrameOptions& options) {
  check_options(options);
  scene.check();
  const dynamics::Model& model = *scene.model;
  const int ee_frame = scene.end_effector_frame.empty()
                           ? static_cast<int>(model.frames.size()) - 1
                           : model.frame_index(scene.end_effector_frame);
  RenderResult result;
  result.times = scene.trajectory.even_times(options.frames);
  Panel panel;
  panel.width = options.width;
  panel.height = options.height;
  panel.camera = auto_camera(scene, double(options.width) / options.height);
  panel.time = result.times.back();

  std::vector<DrawItem> opaque;
  if (options.floor) {
    const Floor floor = make_floor(scene, panel.camera);
    DrawItem item;
    item.mesh = floor.mesh;
    item.pose = floor.pose;
    opaque.push_back(item);
  }
  for (const DrawItem& item : obstacle_items(scene)) opaque.push_back(item);
  if (ee_frame >= 0) {
    const double radius = std::max(0.0035 * motion_bounds(scene).diagonal().norm(), 1e-3);
    DrawItem path;
    path.mesh = renderer_.upload("ee_path", make_tube(path_points(scene, ee_frame), radius));
    path.color = options.path_color;
    opaque.push_back(path);
  }
  dynamics::Data data(model);
  robot_items(model, data, scene.trajectory.at(result.times.back()), opaque);

  // Ghosts back to front so that nearer ones blend over farther ones.
  struct Ghost {
    std::vector<DrawItem> items;
    float alpha;
    double distance;
  };
  std::vector<Ghost> ghosts;
  const int n = options.frames;
  for (int i = 0; i + 1 < n; ++i) {
    Ghost ghost;
    robot_items(model, data, scene.trajectory.at(result.times[i]), ghost.items);
    ghost.alpha = options.ghost_min_alpha + (1.f - options.ghost_min_alpha) *
                                                static_cast<float>(i) / static_cast<float>(n - 1);
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const Eigen::Isometry3d& pose : data.body_pose) centre += pose.translation();
    if (!data.body_pose.empty()) centre /= static_cast<double>(data.body_pose.size());
    ghost.distance = (centre - panel.camera.eye).norm();
    ghosts.push_back(std::move(ghost));
  }
  std::stable_sort(ghosts.begin(), ghosts.end(),
                   [](const Ghost& a, const Ghost& b) { return a.distance > b.distance; });

  renderer_.begin(options.width, options.height, options.background);
  renderer_.set_panel(0, 0, panel.width, panel.height, panel.camera);
  renderer_.draw(opaque);
  for (const Ghost& ghost : ghosts) renderer_.draw_ghost(ghost.items, ghost.alpha);
  result.image = renderer_.finish();
  result.panels.push_back(panel);
  if (options.labels) {
    const double size = std::clamp(options.height * 0.04, 11.0, 26.0);
    draw_label(result.image,
               fmt::format("t = {:.2f} \u2192 {:.2f} s, {} poses", result.times.front(),
                           result.times.back(), n),
               0.5 * options.width, 0.3 * size, size);
  }
  return result;
}

}  // namespace kinograph::render

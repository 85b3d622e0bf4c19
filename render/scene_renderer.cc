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

Eigen::AlignedBox3d bounds_of(const std::vector<Eigen::Vector3d>& points) {
  Eigen::AlignedBox3d bounds;
  for (const Eigen::Vector3d& p : points) bounds.extend(p);
  // A robot with no visual geometry (or a point) still gets a finite frame.
  const Eigen::Vector3d pad = (Eigen::Vector3d::Constant(0.1) - bounds.sizes()).cwiseMax(0.0) / 2;
  bounds.min() -= pad;
  bounds.max() += pad;
  return bounds;
}

// The end-effector frame of a scene: its named one, else the model's last frame (-1: none).
int end_effector(const RenderScene& scene) {
  const dynamics::Model& model = *scene.model;
  return scene.end_effector_frame.empty() ? static_cast<int>(model.frames.size()) - 1
                                          : model.frame_index(scene.end_effector_frame);
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

MeshId SceneRenderer::obstacle_mesh(const collision::Shape& shape) {
  Geometry g;
  g.size = shape.size;
  g.mesh_path = shape.mesh_path;
  g.mesh_scale = shape.mesh_scale;
  switch (shape.kind) {
    case collision::ShapeKind::kSphere:
      g.shape = Geometry::Shape::kSphere;
      break;
    case collision::ShapeKind::kBox:
      g.shape = Geometry::Shape::kBox;
      break;
    case collision::ShapeKind::kCylinder:
      g.shape = Geometry::Shape::kCylinder;
      break;
    case collision::ShapeKind::kCapsule:
      g.shape = Geometry::Shape::kCapsule;
      break;
    case collision::ShapeKind::kMesh:
      g.shape = Geometry::Shape::kMesh;
      g.link_name = "obstacle";
      break;
  }
  return geometry_mesh(g);
}

void SceneRenderer::obstacle_items(const RenderScene& scene, double time, bool moving_only,
                                   std::vector<DrawItem>& items) {
  for (const SceneObstacle& o : scene.obstacles) {
    if (moving_only && !o.obstacle.is_moving()) continue;
    DrawItem item;
    item.mesh = obstacle_mesh(o.obstacle.shape);
    item.pose = o.obstacle.pose_at(time);
    item.color = o.rgba.cast<float>();
    items.push_back(item);
  }
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
  const std::vector<double> times = scene.trajectory.even_times(samples);
  for (double t : times) {
    dynamics::forward_kinematics(model, data, scene.trajectory.at(t));
    for (const Geometry& g : model.visual) {
      add_box(renderer_.mesh_bounds(geometry_mesh(g)), geometry_pose(g, data));
    }
    for (const Eigen::Isometry3d& pose : data.body_pose) points.push_back(pose.translation());
  }
  for (const SceneObstacle& o : scene.obstacles) {
    const Eigen::AlignedBox3d& box = renderer_.mesh_bounds(obstacle_mesh(o.obstacle.shape));
    if (!o.obstacle.is_moving()) {
      add_box(box, o.obstacle.pose);
      continue;
    }
    for (double t : times) add_box(box, o.obstacle.pose_at(t));
  }
  if (points.empty()) points.push_back(Eigen::Vector3d::Zero());
  return points;
}

Eigen::AlignedBox3d SceneRenderer::motion_bounds(const RenderScene& scene) {
  return bounds_of(motion_points(scene));
}

Camera SceneRenderer::auto_camera(const RenderScene& scene, double aspect) {
  if (scene.camera) return *scene.camera;
  return camera_for(scene, motion_points(scene), aspect);
}

Camera SceneRenderer::camera_for(const RenderScene& scene,
                                 const std::vector<Eigen::Vector3d>& points, double aspect) {
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
  return frame_points(points, view_dir.normalized(), aspect, up);
}

SceneRenderer::Floor SceneRenderer::make_floor(const Eigen::AlignedBox3d& bounds,
                                               const Camera& camera) {
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
  const std::vector<Eigen::Vector3d> points = motion_points(scene);
  const Camera camera = camera_for(scene, points, double(panel_w) / options.height);
  std::vector<DrawItem> fixed;
  if (options.floor) {
    const Floor floor = make_floor(bounds_of(points), camera);
    DrawItem item;
    item.mesh = floor.mesh;
    item.pose = floor.pose;
    fixed.push_back(item);
  }

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
    obstacle_items(scene, panel.time, false, items);  // moving ones where they are now
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
  Layer layer;
  layer.scene = &scene;
  layer.min_alpha = options.ghost_min_alpha;
  layer.path_color = options.path_color;
  layer.path_key = "ee_path";
  const std::vector<Eigen::Vector3d> points = motion_points(scene);
  const Camera camera = camera_for(scene, points, double(options.width) / options.height);
  RenderResult result = overlay({layer}, camera, points, options);
  if (options.labels) {
    const double size = std::clamp(options.height * 0.04, 11.0, 26.0);
    draw_label(result.image,
               fmt::format("t = {:.2f} \u2192 {:.2f} s, {} poses", result.times.front(),
                           result.times.back(), options.frames),
               0.5 * options.width, 0.3 * size, size);
  }
  return result;
}

RenderResult SceneRenderer::compare(const RenderScene& before, const RenderScene& after,
                                    const CompareOptions& options) {
  const FrameOptions& frame = options.frame;
  check_options(frame);
  before.check();
  after.check();
  if (before.model->nq() != after.model->nq()) {
    throw std::invalid_argument(
        fmt::format("render: the plans to compare have robots of {} and {} joints",
                    before.model->nq(), after.model->nq()));
  }
  Layer first;
  first.scene = &before;
  first.tint = options.before_color;
  first.min_alpha = options.before_min_alpha;
  first.max_alpha = std::min(options.before_max_alpha, 0.99f);  // a ghost, never solid
  first.obstacles = false;  // the world the second plan was made for is the one that counts
  first.path_color = options.before_path_color;
  first.path_key = "ee_path_before";
  first.path_radius = options.path_radius;
  for (const SceneObstacle& o : before.obstacles) {
    const bool kept = std::any_of(after.obstacles.begin(), after.obstacles.end(),
                                  [&](const SceneObstacle& a) { return a.name == o.name; });
    if (!kept) first.faded.push_back(o);
  }
  RenderScene shown = after;
  const int changed = options.changed_color
                          ? highlight_changed_obstacles(before, shown, *options.changed_color)
                          : 0;
  Layer second;
  second.scene = &shown;
  second.min_alpha = frame.ghost_min_alpha;
  second.path_color = frame.path_color;
  second.path_key = "ee_path";
  second.path_radius = options.path_radius;
  std::vector<Eigen::Vector3d> points = motion_points(after);
  for (const Eigen::Vector3d& p : motion_points(before)) points.push_back(p);
  const double aspect = double(frame.width) / frame.height;
  Camera camera = camera_for(after, points, aspect);
  if (after.camera && options.reframe_camera) {
    camera = frame_points(points, (camera.eye - camera.target).normalized(), aspect, camera.up,
                          camera.fov_y_deg);
  }
  RenderResult result = overlay({first, second}, camera, points, frame);
  if (frame.labels) {
    // The legend in the bottom-left corner, where a view from above shows only floor.
    const double size = std::clamp(frame.height * 0.035, 11.0, 24.0);
    std::vector<std::pair<std::string, Eigen::Vector3d>> lines = {
        {options.before_label, options.before_path_color.head<3>().cast<double>()},
        {options.after_label, frame.path_color.head<3>().cast<double>()}};
    if (changed > 0) lines.emplace_back(options.changed_label, options.changed_color->head<3>());
    if (!first.faded.empty()) {
      lines.emplace_back(options.removed_label, first.faded.front().rgba.head<3>());
    }
    double y = frame.height - (1.5 * static_cast<double>(lines.size() - 1) + 2.4) * size;
    for (const auto& [text, color] : lines) {
      draw_label(result.image, text, 0.5 * size, y, size, LabelAnchor::kTopLeft, color);
      y += 1.5 * size;
    }
  }
  return result;
}

RenderResult SceneRenderer::overlay(const std::vector<Layer>& layers, const Camera& camera,
                                    const std::vector<Eigen::Vector3d>& points,
                                    const FrameOptions& options) {
  RenderResult result;
  Panel panel;
  panel.width = options.width;
  panel.height = options.height;
  panel.camera = camera;
  const Eigen::AlignedBox3d bounds = bounds_of(points);

  std::vector<DrawItem> opaque;
  if (options.floor) {
    const Floor floor = make_floor(bounds, camera);
    DrawItem item;
    item.mesh = floor.mesh;
    item.pose = floor.pose;
    opaque.push_back(item);
  }
  // Ghosts back to front so that nearer ones blend over farther ones.
  struct Ghost {
    std::vector<DrawItem> items;
    float alpha;
    double distance;
  };
  std::vector<Ghost> ghosts;
  const int n = options.frames;
  for (const Layer& layer : layers) {
    const RenderScene& scene = *layer.scene;
    const dynamics::Model& model = *scene.model;
    const std::vector<double> times = scene.trajectory.even_times(n);
    std::vector<ScenePath> paths = scene.paths;
    if (paths.empty() && end_effector(scene) >= 0) {
      paths.push_back({model.frames[end_effector(scene)].name, layer.path_color});
    }
    for (std::size_t p = 0; p < paths.size(); ++p) {
      const double radius = std::max(layer.path_radius * bounds.diagonal().norm(), 1e-3);
      const std::string key = p == 0 ? layer.path_key : layer.path_key + ":" + std::to_string(p);
      DrawItem path;
      path.mesh = renderer_.upload(
          key, make_tube(path_points(scene, model.frame_index(paths[p].frame)), radius));
      path.color = paths[p].rgba;
      opaque.push_back(path);
    }
    // Fixed obstacles once; moving ones where they are at each pose's time, faded with it.
    if (layer.obstacles) {
      for (const SceneObstacle& o : scene.obstacles) {
        if (o.obstacle.is_moving()) continue;
        DrawItem item;
        item.mesh = obstacle_mesh(o.obstacle.shape);
        item.pose = o.obstacle.pose;
        item.color = o.rgba.cast<float>();
        opaque.push_back(item);
      }
    }
    if (!layer.faded.empty()) {
      Ghost ghost;
      ghost.alpha = layer.min_alpha;
      RenderScene faded;
      faded.obstacles = layer.faded;
      obstacle_items(faded, times.front(), false, ghost.items);
      ghost.distance = (bounds.center() - camera.eye).norm();
      ghosts.push_back(std::move(ghost));
    }
    dynamics::Data data(model);
    for (int i = 0; i < n; ++i) {
      const float alpha = n == 1 ? layer.max_alpha
                                 : layer.min_alpha + (layer.max_alpha - layer.min_alpha) *
                                                         static_cast<float>(i) /
                                                         static_cast<float>(n - 1);
      Ghost ghost;
      ghost.alpha = alpha;
      robot_items(model, data, scene.trajectory.at(times[i]), ghost.items);
      if (layer.tint) {
        for (DrawItem& item : ghost.items) {
          item.color = *layer.tint;
          item.use_mesh_colors = false;
        }
      }
      if (layer.obstacles) obstacle_items(scene, times[i], true, ghost.items);
      if (alpha >= 1.f) {
        opaque.insert(opaque.end(), ghost.items.begin(), ghost.items.end());
        continue;
      }
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (const Eigen::Isometry3d& pose : data.body_pose) centre += pose.translation();
      if (!data.body_pose.empty()) centre /= static_cast<double>(data.body_pose.size());
      ghost.distance = (centre - camera.eye).norm();
      ghosts.push_back(std::move(ghost));
    }
    result.times = times;  // the last layer's (the plan drawn in colour)
    panel.time = std::max(panel.time, times.back());
  }
  std::stable_sort(ghosts.begin(), ghosts.end(),
                   [](const Ghost& a, const Ghost& b) { return a.distance > b.distance; });

  renderer_.begin(options.width, options.height, options.background);
  renderer_.set_panel(0, 0, panel.width, panel.height, panel.camera);
  renderer_.draw(opaque);
  for (const Ghost& ghost : ghosts) renderer_.draw_ghost(ghost.items, ghost.alpha);
  result.image = renderer_.finish();
  result.panels.push_back(panel);
  return result;
}

}  // namespace kinograph::render

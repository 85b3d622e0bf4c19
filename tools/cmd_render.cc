// `kinograph render plan.json --frames 5 --style strip|ghost --out strip.png`: draws a plan
// headlessly (OSMesa) as a frame strip or a ghost overlay; `--compare after.json` draws a plan
// and its replan in one view (the replanning figure). A failed plan's picture is marked failed.
// `kinograph render scene.yaml` or `robot.urdf` draws the start pose (or the robot at rest).
#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>

#include "kinograph/planning/io/plan_json.h"
#include "render/failure_mark.h"
#include "render/image.h"
#include "render/plan_scene.h"
#include "render/scene_camera.h"
#include "render/scene_renderer.h"
#include "render/start_scene.h"
#include "tools/command_registry.h"
#include "tools/picture_options.h"
#include "tools/plan_file.h"

namespace kinograph::tools {
namespace {

struct RenderArgs : PictureArgs {
  std::string plan;
  std::string compare;
  std::string scene;
  std::string ee_frame;
  std::string before_label = "before: grey poses, green path";
  std::string after_label = "after: robot colours, red path";
};

// A scene file's start pose among its obstacles, or a URDF's robot at rest: one picture.
void render_still(const RenderArgs& args, const std::string& extension) {
  if (!args.compare.empty()) throw CommandFailure("--compare needs two plan files (.json)");
  std::optional<planning::Scene> scene;
  dynamics::Model robot;
  render::RenderScene picture;
  if (extension == ".urdf") {
    robot = dynamics::Model::from_urdf_file(args.plan);
    picture = render::robot_scene(robot);
  } else {
    scene = planning::load_scene(args.plan);
    picture = render::start_scene(*scene);
  }
  if (!args.scene.empty()) picture.camera = render::read_scene_camera(args.scene);
  picture.end_effector_frame = args.ee_frame;
  render::SceneRenderer renderer = make_renderer(args);
  render::write_png(renderer.strip(picture, frame_options(args, 1)).image, args.out);
}

void run_render(const RenderArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  const std::string extension = std::filesystem::path(args.plan).extension().string();
  if (extension != ".json" && extension != ".yaml" && extension != ".yml" && extension != ".urdf") {
    throw CommandFailure(args.plan + ": not a plan (.json), scene (.yaml) or robot (.urdf)");
  }
  try {
    if (extension != ".json") {
      render_still(args, extension);
      spdlog::info("render: wrote {} ({}x{}, the start pose of {})", args.out, args.width,
                   args.height, args.plan);
      return;
    }
    const planning::PlanFile plan = planning::read_plan_file(args.plan);
    render::RenderScene scene = render::plan_scene(plan);
    scene.end_effector_frame = args.ee_frame;
    // The scene's camera: --scene's, else that of the scene the plan file names.
    const std::optional<std::string> scene_file =
        args.scene.empty() ? plan_scene_path(args.plan) : std::optional<std::string>(args.scene);
    if (scene_file) scene.camera = render::read_scene_camera(*scene_file);
    const render::FrameOptions options = frame_options(args, args.frames);
    render::SceneRenderer renderer = make_renderer(args);
    render::RenderResult result;
    std::optional<std::string> failure = render::failure_text(plan.plan);
    if (!args.compare.empty()) {
      const planning::PlanFile after_plan = planning::read_plan_file(args.compare);
      if (!failure) failure = render::failure_text(after_plan.plan);
      render::RenderScene after = render::plan_scene(after_plan);
      after.end_effector_frame = args.ee_frame;
      after.camera = scene.camera;
      render::CompareOptions compare;
      compare.frame = options;
      compare.before_label = args.before_label;
      compare.after_label = args.after_label;
      result = renderer.compare(scene, after, compare);
    } else if (args.style == "ghost") {
      result = renderer.ghost(scene, options);
    } else {
      result = renderer.strip(scene, options);
    }
    if (failure) render::mark_failed(result.image, *failure);
    render::write_png(result.image, args.out);
  } catch (const std::exception& e) {
    throw CommandFailure(e.what());
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::info("render: wrote {} ({}x{}, {} frames, {}) in {:.3f} s", args.out, args.width,
               args.height, args.frames, args.compare.empty() ? args.style : "compare", seconds);
}

const bool kRenderRegistered = register_command([](CLI::App& root) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = root.add_subcommand(
      "render",
      "Draw a plan as a frame strip or a ghost overlay PNG, or a scene's start pose or a robot "
      "(headless, OSMesa)");
  cmd->add_option("plan", args->plan,
                  "Plan file (.json) written by the planner; or a scene (.yaml: its start pose "
                  "among its obstacles) or a robot (.urdf: at rest), drawn as one picture")
      ->required();
  cmd->add_option("--compare", args->compare,
                  "Second plan file (e.g. the replan): both in one view, the first as grey "
                  "ghosts, the second in colour among its obstacles (changed ones highlighted)");
  cmd->add_option("--scene", args->scene,
                  "Scene file (YAML) whose optional 'camera' block (eye, target, up, fov_y_deg) "
                  "replaces the automatic framing; default: the scene the plan file names");
  add_picture_options(cmd, *args);
  cmd->add_option("--ee-frame", args->ee_frame,
                  "Frame whose path a ghost overlay draws (default: the model's last frame)");
  cmd->add_option("--before-label", args->before_label, "Legend line of the plan (--compare)")
      ->capture_default_str();
  cmd->add_option("--after-label", args->after_label, "Legend line of the --compare plan")
      ->capture_default_str();
  cmd->callback([args] { run_render(*args); });
});

}  // namespace
}  // namespace kinograph::tools

// `kinograph render plan.json --frames 5 --style strip|ghost --out strip.png`: draws a plan
// headlessly (OSMesa) as a frame strip or a ghost overlay; `--compare after.json` draws a plan
// and its replan in one view (the replanning figure). A failed plan's picture is marked failed.
#include <spdlog/spdlog.h>

#include <chrono>
#include <optional>
#include <string>

#include "kinograph/planning/io/plan_json.h"
#include "render/failure_mark.h"
#include "render/image.h"
#include "render/plan_scene.h"
#include "render/scene_camera.h"
#include "render/scene_renderer.h"
#include "tools/command_registry.h"
#include "tools/plan_file.h"
#include "tools/png_path.h"

namespace kinograph::tools {
namespace {

struct RenderArgs {
  std::string plan;
  std::string compare;
  std::string scene;
  std::string out = "strip.png";
  std::string style = "strip";
  std::string ee_frame;
  std::string before_label = "before: grey poses, green path";
  std::string after_label = "after: robot colours, red path";
  int frames = 5;
  int width = 1600;
  int height = 400;
  int samples = 4;
  bool no_labels = false;
  bool no_floor = false;
};

void run_render(const RenderArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  try {
    const planning::PlanFile plan = planning::read_plan_file(args.plan);
    render::RenderScene scene = render::plan_scene(plan);
    scene.end_effector_frame = args.ee_frame;
    // The scene's camera: --scene's, else that of the scene the plan file names.
    const std::optional<std::string> scene_file =
        args.scene.empty() ? plan_scene_path(args.plan) : std::optional<std::string>(args.scene);
    if (scene_file) scene.camera = render::read_scene_camera(*scene_file);
    render::FrameOptions options;
    options.frames = args.frames;
    options.width = args.width;
    options.height = args.height;
    options.labels = !args.no_labels;
    options.floor = !args.no_floor;
    render::SceneRenderer renderer(render::RendererOptions{.samples = args.samples});
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

const bool kRegistered = register_command([](CLI::App& root) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = root.add_subcommand(
      "render", "Draw a plan as a frame strip or a ghost overlay PNG (headless, OSMesa)");
  cmd->add_option("plan", args->plan, "Plan file (JSON) written by the planner")->required();
  cmd->add_option("--compare", args->compare,
                  "Second plan file (e.g. the replan): both in one view, the first as grey "
                  "ghosts, the second in colour among its obstacles (changed ones highlighted)");
  cmd->add_option("--scene", args->scene,
                  "Scene file (YAML) whose optional 'camera' block (eye, target, up, fov_y_deg) "
                  "replaces the automatic framing; default: the scene the plan file names");
  cmd->add_option("--frames", args->frames, "Number of robot poses, evenly spaced in time")
      ->capture_default_str();
  cmd->add_option("--style", args->style, "strip (side by side) or ghost (one overlaid view)")
      ->check(CLI::IsMember({"strip", "ghost"}))
      ->capture_default_str();
  cmd->add_option("--width", args->width, "Picture width, pixels")->capture_default_str();
  cmd->add_option("--height", args->height, "Picture height, pixels")->capture_default_str();
  cmd->add_option("--out", args->out, "Output picture (.png)")
      ->check(png_path())
      ->capture_default_str();
  cmd->add_option("--ee-frame", args->ee_frame,
                  "Frame whose path a ghost overlay draws (default: the model's last frame)");
  cmd->add_option("--before-label", args->before_label, "Legend line of the plan (--compare)")
      ->capture_default_str();
  cmd->add_option("--after-label", args->after_label, "Legend line of the --compare plan")
      ->capture_default_str();
  cmd->add_option("--samples", args->samples, "MSAA samples per pixel")->capture_default_str();
  cmd->add_flag("--no-labels", args->no_labels, "Leave out the time labels and the legend");
  cmd->add_flag("--no-floor", args->no_floor, "Leave out the checker floor / backdrop");
  cmd->callback([args] { run_render(*args); });
});

}  // namespace
}  // namespace kinograph::tools

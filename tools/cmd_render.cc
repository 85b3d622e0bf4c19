// `kinograph render plan.json --frames 5 --style strip|ghost --out strip.png`: draws a plan
// headlessly (OSMesa) as a frame strip or a ghost overlay.
#include <spdlog/spdlog.h>

#include <chrono>
#include <string>

#include "render/image.h"
#include "render/plan_json.h"
#include "render/scene_camera.h"
#include "render/scene_renderer.h"
#include "tools/command_registry.h"

namespace kinograph::tools {
namespace {

struct RenderArgs {
  std::string plan;
  std::string scene;
  std::string out = "strip.png";
  std::string style = "strip";
  std::string ee_frame;
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
    const render::PlanFile plan = render::read_plan_json(args.plan);
    const dynamics::Model model = render::load_plan_model(plan);
    render::RenderScene scene;
    scene.model = &model;
    scene.trajectory = render::plan_trajectory(plan, model);
    scene.obstacles = render::plan_obstacles(plan);
    scene.end_effector_frame = args.ee_frame;
    if (!args.scene.empty()) scene.camera = render::read_scene_camera(args.scene);
    render::FrameOptions options;
    options.frames = args.frames;
    options.width = args.width;
    options.height = args.height;
    options.labels = !args.no_labels;
    options.floor = !args.no_floor;
    render::SceneRenderer renderer(render::RendererOptions{.samples = args.samples});
    const render::RenderResult result =
        args.style == "ghost" ? renderer.ghost(scene, options) : renderer.strip(scene, options);
    render::write_png(result.image, args.out);
  } catch (const std::exception& e) {
    throw CommandFailure(e.what());
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::info("render: wrote {} ({}x{}, {} frames, {}) in {:.3f} s", args.out, args.width,
               args.height, args.frames, args.style, seconds);
}

const bool kRegistered = register_command([](CLI::App& root) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = root.add_subcommand(
      "render", "Draw a plan as a frame strip or a ghost overlay PNG (headless, OSMesa)");
  cmd->add_option("plan", args->plan, "Plan file (JSON) written by the planner")->required();
  cmd->add_option("--scene", args->scene,
                  "Scene file (YAML); its optional 'camera' block (eye, target, up, fov_y_deg) "
                  "replaces the automatic framing");
  cmd->add_option("--frames", args->frames, "Number of robot poses, evenly spaced in time")
      ->capture_default_str();
  cmd->add_option("--style", args->style, "strip (side by side) or ghost (one overlaid view)")
      ->check(CLI::IsMember({"strip", "ghost"}))
      ->capture_default_str();
  cmd->add_option("--width", args->width, "Picture width, pixels")->capture_default_str();
  cmd->add_option("--height", args->height, "Picture height, pixels")->capture_default_str();
  cmd->add_option("--out", args->out, "Output PNG")->capture_default_str();
  cmd->add_option("--ee-frame", args->ee_frame,
                  "Frame whose path a ghost overlay draws (default: the model's last frame)");
  cmd->add_option("--samples", args->samples, "MSAA samples per pixel")->capture_default_str();
  cmd->add_flag("--no-labels", args->no_labels, "Leave out the time labels");
  cmd->add_flag("--no-floor", args->no_floor, "Leave out the checker floor / backdrop");
  cmd->callback([args] { run_render(*args); });
});

}  // namespace
}  // namespace kinograph::tools

#include "tools/picture_options.h"

#include "tools/png_path.h"

namespace kinograph::tools {

void add_picture_options(CLI::App* cmd, PictureArgs& args) {
  cmd->add_option("--frames", args.frames, "Number of robot poses, evenly spaced in time")
      ->capture_default_str();
  cmd->add_option("--style", args.style, "strip (side by side) or ghost (one overlaid view)")
      ->check(CLI::IsMember({"strip", "ghost"}))
      ->capture_default_str();
  cmd->add_option("--width", args.width, "Picture width, pixels")->capture_default_str();
  cmd->add_option("--height", args.height, "Picture height, pixels")->capture_default_str();
  cmd->add_option("--out", args.out, "Output picture (.png)")
      ->check(png_path())
      ->capture_default_str();
  cmd->add_option("--samples", args.samples, "MSAA samples per pixel")->capture_default_str();
  cmd->add_flag("--no-labels", args.no_labels, "Leave out the time labels and the legend");
  cmd->add_flag("--no-floor", args.no_floor, "Leave out the checker floor / backdrop");
}

render::FrameOptions frame_options(const PictureArgs& args, int frames) {
  render::FrameOptions options;
  options.frames = frames;
  options.width = args.width;
  options.height = args.height;
  options.labels = !args.no_labels;
  options.floor = !args.no_floor;
  return options;
}

render::SceneRenderer make_renderer(const PictureArgs& args) {
  return render::SceneRenderer(render::RendererOptions{.samples = args.samples});
}

}  // namespace kinograph::tools

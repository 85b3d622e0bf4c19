#pragma once
// The picture options of the drawing verbs (render, render-cell): output file, style, size,
// poses, labels, floor, and the frame options and renderer they make.
#include <CLI/CLI.hpp>
#include <string>

#include "render/scene_renderer.h"

namespace kinograph::tools {

/// What a drawing verb's picture looks like; defaults give a 5-pose 1600×400 strip.
struct PictureArgs {
  std::string out = "strip.png";
  std::string style = "strip";  ///< "strip" or "ghost"
  int frames = 5;
  int width = 1600;
  int height = 400;
  int samples = 4;
  bool no_labels = false;
  bool no_floor = false;
};

/// Adds --out, --style, --frames, --width, --height, --samples, --no-labels and --no-floor.
void add_picture_options(CLI::App* cmd, PictureArgs& args);

/// The frame options of `args` with `frames` poses.
render::FrameOptions frame_options(const PictureArgs& args, int frames);

/// A renderer with the requested MSAA samples.
render::SceneRenderer make_renderer(const PictureArgs& args);

}  // namespace kinograph::tools

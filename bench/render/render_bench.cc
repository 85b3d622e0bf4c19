// Renderer benchmark: a 5-frame iiwa strip at 1600×400 including PNG writing (target: under
// 0.5 s). Reports the cold first picture (context creation, shader JIT, mesh upload)
// separately from warm pictures, with medians over repeated runs. Prints JSON, then a Markdown
// table.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "kinograph/dynamics/model.h"
#include "render/image.h"
#include "render/plot.h"
#include "render/scene_renderer.h"

namespace {

using Clock = std::chrono::steady_clock;
using kinograph::render::FrameOptions;
using kinograph::render::RenderScene;
using kinograph::render::SceneRenderer;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The iiwa moving between two configurations (minimum-jerk), beside a desk.
kinograph::render::RenderScene iiwa_scene(const kinograph::dynamics::Model& model) {
  kinograph::render::RenderScene scene;
  scene.model = &model;
  Eigen::VectorXd q0(7), q1(7);
  q0 << 0.0, 0.3, 0.0, -1.2, 0.0, 0.8, 0.0;
  q1 << 1.8, -0.4, 0.3, -1.6, 0.2, 1.0, 0.5;
  for (int k = 0; k <= 50; ++k) {
    const double s = k / 50.0, h = s * s * s * (10 - 15 * s + 6 * s * s);
    scene.trajectory.t.push_back(2.5 * s);
    scene.trajectory.q.push_back(q0 + h * (q1 - q0));
  }
  kinograph::render::SceneObstacle desk;
  desk.name = "desk";
  desk.obstacle.shape = kinograph::collision::Shape::box(0.6, 0.8, 0.4);
  desk.obstacle.pose.translation() = Eigen::Vector3d(0.7, 0.5, 0.2);
  scene.obstacles.push_back(desk);
  return scene;
}

// Made-up smooth torques on the same clock, for the plot.
kinograph::render::PlotSeries iiwa_torques() {
  kinograph::render::PlotSeries series{"plan", {}, {}};
  for (int k = 0; k <= 50; ++k) {
    const double s = k / 50.0;
    series.t.push_back(2.5 * s);
    Eigen::VectorXd tau(7);
    for (int j = 0; j < 7; ++j) tau[j] = 30 * std::sin(6 * s + j);
    series.values.push_back(tau);
  }
  return series;
}

}  // namespace

int main(int argc, char** argv) {
  const int runs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 15;
  const std::string out =
      (std::filesystem::temp_directory_path() / "kinograph_render_bench.png").string();
  const kinograph::dynamics::Model model = kinograph::dynamics::Model::from_urdf_file(
      std::string(KINOGRAPH_SOURCE_DIR) + "/robots/iiwa14/iiwa14.urdf");
  const RenderScene scene = iiwa_scene(model);
  const kinograph::render::PlotSeries torques = iiwa_torques();
  const FrameOptions options;  // 5 frames, 1600×400

  // Cold: a fresh renderer (context, shaders JIT-compiled on first draw, meshes uploaded).
  auto start = Clock::now();
  SceneRenderer renderer;
  const double context_s = seconds_since(start);
  start = Clock::now();
  kinograph::render::write_png(renderer.strip(scene, options).image, out);
  const double cold_s = seconds_since(start) + context_s;

  std::vector<double> total, render, png, ghost, plot;
  for (int i = 0; i < runs; ++i) {
    start = Clock::now();
    const auto result = renderer.strip(scene, options);
    render.push_back(seconds_since(start));
    const auto png_start = Clock::now();
    kinograph::render::write_png(result.image, out);
    png.push_back(seconds_since(png_start));
    total.push_back(seconds_since(start));
    start = Clock::now();
    kinograph::render::write_png(renderer.ghost(scene, options).image, out);
    ghost.push_back(seconds_since(start));
    start = Clock::now();
    kinograph::render::write_png(kinograph::render::plot_torques({torques}, {}), out);
    plot.push_back(seconds_since(start));
  }
  std::filesystem::remove(out);

  std::printf(
      "{\"benchmark\": \"render_iiwa_strip\", \"renderer\": \"%s\", \"runs\": %d, "
      "\"width\": %d, \"height\": %d, \"frames\": %d,\n"
      " \"context_s\": %.4f, \"cold_first_strip_with_png_s\": %.4f,\n"
      " \"median_strip_with_png_s\": %.4f, \"median_render_s\": %.4f, \"median_png_s\": %.4f,\n"
      " \"median_ghost_with_png_s\": %.4f, \"median_torque_plot_with_png_s\": %.4f}\n\n",
      renderer.renderer().renderer_name(), runs, options.width, options.height, options.frames,
      context_s, cold_s, median(total), median(render), median(png), median(ghost), median(plot));
  std::printf("| measurement (iiwa, 5 frames, 1600x400) | median s |\n|---|---|\n");
  std::printf("| strip incl. PNG (warm) | %.4f |\n", median(total));
  std::printf("| ... GL render + readback + labels | %.4f |\n", median(render));
  std::printf("| ... PNG encode + write | %.4f |\n", median(png));
  std::printf("| ghost overlay incl. PNG (warm) | %.4f |\n", median(ghost));
  std::printf("| torque plot incl. PNG | %.4f |\n", median(plot));
  std::printf("| cold: context + first strip incl. PNG (one run) | %.4f |\n", cold_s);
  return 0;
}

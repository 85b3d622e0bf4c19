// `kinograph plot plan.json [other.json] --out torque.png`: joint torques over time, one
// subplot per joint, axes spanning the torques, effort limits dashed where within them (else
// named at the edge), a second plan overlaid for comparison.
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "kinograph/planning/io/plan_json.h"
#include "render/image.h"
#include "render/plot.h"
#include "tools/command_registry.h"
#include "tools/png_path.h"

namespace kinograph::tools {
namespace {

struct PlotArgs {
  std::vector<std::string> plans;
  std::vector<std::string> labels;
  std::string out = "torque.png";
  std::string title = "Joint torques";
  int width = 1200;
  int height = 0;
};

void run_plot(const PlotArgs& args) {
  try {
    std::vector<render::PlotSeries> series;
    render::TorquePlotOptions options;
    options.title = args.title;
    options.width = args.width;
    options.height = args.height;
    for (std::size_t i = 0; i < args.plans.size(); ++i) {
      const planning::PlanFile file = planning::read_plan_file(args.plans[i]);
      render::PlotSeries s;
      s.label = i < args.labels.size()    ? args.labels[i]
                : !file.info.name.empty() ? file.info.name
                                          : std::filesystem::path(args.plans[i]).stem().string();
      if (args.plans.size() == 2 && i == 1 && s.label == series.front().label) {
        s.label = std::filesystem::path(args.plans[i]).stem().string();  // keep legends apart
      }
      s.t = file.plan.t;
      for (Eigen::Index k = 0; k < file.plan.tau.rows(); ++k) {
        s.values.push_back(file.plan.tau.row(k).transpose());
      }
      series.push_back(std::move(s));
      if (i == 0) {
        // Columns come in the robot's joint order, with the plan's (scene's) effort limits.
        bool any_limit = false;
        for (const dynamics::Body& body : file.model->bodies) {
          options.joint_names.push_back(body.joint_name);
          options.limits.push_back(body.limits.effort);
          any_limit = any_limit || std::isfinite(body.limits.effort);
        }
        if (!any_limit) options.limits.clear();
      }
    }
    render::write_png(render::plot_torques(series, options), args.out);
  } catch (const std::exception& e) {
    throw CommandFailure(e.what());
  }
  spdlog::info("plot: wrote {}", args.out);
}

const bool kPlotRegistered = register_command([](CLI::App& root) {
  auto args = std::make_shared<PlotArgs>();
  CLI::App* cmd = root.add_subcommand(
      "plot", "Plot a plan's joint torques (and overlay a second plan) as a PNG");
  cmd->add_option("plans", args->plans, "One or two plan files (JSON)")->required()->expected(1, 2);
  cmd->add_option("--out", args->out, "Output picture (.png)")
      ->check(png_path())
      ->capture_default_str();
  cmd->add_option(
      "--label", args->labels,
      "Legend name of each plan, in order (default: the plan's name, else the file name)");
  cmd->add_option("--title", args->title, "Plot title")->capture_default_str();
  cmd->add_option("--width", args->width, "Picture width, pixels")->capture_default_str();
  cmd->add_option("--height", args->height, "Picture height, pixels (0: from the joint count)")
      ->capture_default_str();
  cmd->callback([args] { run_plot(*args); });
});

}  // namespace
}  // namespace kinograph::tools

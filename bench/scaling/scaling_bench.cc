// How a batch plan's cost grows with the number of steps: the iiwa desk scene (task 1, 3 s) and
// the Acrobot swing-up (10 s) planned at 25 to 1000 steps in both formulations, with CPU time
// per LM iteration and a least-squares line through it (a trajectory graph is block-banded, so
// one iteration should cost time linear in the steps).
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bench/common/bench_flags.h"
#include "bench/common/bench_stats.h"
#include "bench/common/cpu_clock.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/io/scene.h"
#include "render/image.h"
#include "render/plot.h"

using nlohmann::json;
namespace planning = kinograph::planning;

namespace {

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) out.push_back(item);
  if (out.empty()) throw std::invalid_argument(text);
  return out;
}

std::vector<int> parse_list(const std::string& text) {
  std::vector<int> out;
  for (const std::string& item : split(text)) out.push_back(std::stoi(item));
  return out;
}

bool wanted(const std::vector<std::string>& names, const std::string& name) {
  return names.empty() || std::find(names.begin(), names.end(), name) != names.end();
}

// CPU per iteration against steps: one subplot per robot, one curve per formulation, over the
// steps at which every robot's plan iterated.
void write_plot(const json& result, const std::vector<std::string>& robots,
                const std::vector<std::string>& formulations, const std::string& path) {
  std::vector<kinograph::render::PlotSeries> series;
  for (const std::string& f : formulations) {
    kinograph::render::PlotSeries s;
    s.label = f;
    const std::vector<int> steps = result["steps"].get<std::vector<int>>();
    for (size_t i = 0; i < steps.size(); ++i) {
      Eigen::VectorXd v(static_cast<Eigen::Index>(robots.size()));
      for (size_t r = 0; r < robots.size(); ++r) {
        v[static_cast<Eigen::Index>(r)] =
            kinograph::bench::json_number(result[robots[r]][f][i]["cpu_ms_per_iteration"]);
      }
      if (!v.allFinite()) continue;
      s.t.push_back(steps[i]);
      s.values.push_back(v);
    }
    if (!s.t.empty()) series.push_back(std::move(s));
  }
  if (series.empty()) return;
  kinograph::render::TorquePlotOptions options;
  options.title = "CPU per LM iteration against the number of steps";
  options.y_label = "ms per iteration";
  options.x_label = "steps";
  options.joint_names = robots;
  options.columns = static_cast<int>(robots.size());
  kinograph::render::write_png(kinograph::render::plot_torques(series, options), path);
}

/// y ≈ a + b·x by least squares, with R².
struct Line {
  double intercept = NAN, slope = NAN, r2 = NAN;
};
Line fit(const std::vector<double>& x, const std::vector<double>& y) {
  const std::size_t n = x.size();
  if (n < 2) return {};
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sx += x[i];
    sy += y[i];
    sxx += x[i] * x[i];
    sxy += x[i] * y[i];
  }
  Line l;
  l.slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  l.intercept = (sy - l.slope * sx) / n;
  double ss_res = 0, ss_tot = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double e = y[i] - (l.intercept + l.slope * x[i]);
    ss_res += e * e;
    ss_tot += (y[i] - sy / n) * (y[i] - sy / n);
  }
  l.r2 = ss_tot > 0 ? 1 - ss_res / ss_tot : 1.0;
  return l;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> steps = {25, 50, 100, 200, 400, 1000};
  std::string json_path, png_path;
  std::vector<std::string> only_robots, only_formulations;
  bool quick = false;
  kinograph::bench::Flags flags("scaling_bench");
  flags.value("--steps", "N,N,...", [&](const std::string& v) { steps = parse_list(v); })
      .value("--json", &json_path)
      .value("--png", &png_path)
      .value("--robots", "iiwa,acrobot", [&](const std::string& v) { only_robots = split(v); })
      .value("--formulations", "condensed,dfg",
             [&](const std::string& v) { only_formulations = split(v); })
      .toggle("--quick", [&] { quick = true; });
  if (!flags.parse(argc, argv)) return 64;
  if (quick) steps = {25, 50, 100};
  spdlog::set_level(spdlog::level::err);

  const std::vector<std::pair<std::string, std::string>> robots = {
      {"iiwa", "iiwa_desk.yaml"}, {"acrobot", "acrobot_swingup.yaml"}};
  const std::vector<planning::Formulation> formulations = {
      planning::Formulation::kCondensed, planning::Formulation::kDynamicFactorGraph};
  json result = {{"steps", steps}};
  std::printf(
      "| robot | formulation | steps | success | LM iterations | CPU (s) | CPU per iteration (ms) "
      "|\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  json fits = json::array();
  std::vector<std::string> plotted_robots, plotted_formulations;
  for (const auto& [robot, scene_file] : robots) {
    if (!wanted(only_robots, robot)) continue;
    plotted_robots.push_back(robot);
    const planning::Scene scene = planning::load_scene(kinograph::bench::kScenes + scene_file);
    for (const planning::Formulation f : formulations) {
      if (!wanted(only_formulations, to_string(f))) continue;
      if (plotted_robots.size() == 1) plotted_formulations.push_back(to_string(f));
      planning::BatchPlannerOptions options;
      options.formulation = f;
      const planning::BatchPlanner planner(options);
      std::vector<double> xs, per_iteration;
      json rows = json::array();
      for (const int n : steps) {
        planning::Problem problem = scene.problem;
        problem.steps = n;
        const double c0 = kinograph::bench::cpu_seconds();
        const planning::Plan plan = planner.plan(problem);
        const double cpu = kinograph::bench::cpu_seconds() - c0;
        const int its = plan.stats.iterations;
        const double ms = its > 0 ? 1e3 * cpu / its : NAN;
        if (its > 0) {
          xs.push_back(n);
          per_iteration.push_back(ms);
        }
        rows.push_back({{"steps", n},
                        {"success", plan.success()},
                        {"iterations", its},
                        {"cpu_s", cpu},
                        {"cpu_ms_per_iteration", ms},
                        {"status", to_string(plan.stats.status)}});
        std::printf("| %s | %s | %d | %s | %d | %.3f | %.3f |\n", robot.c_str(),
                    to_string(f).c_str(), n, plan.success() ? "yes" : "no", its, cpu, ms);
        std::fflush(stdout);
      }
      const Line line = fit(xs, per_iteration);
      fits.push_back({{"robot", robot},
                      {"formulation", to_string(f)},
                      {"ms_per_iteration_intercept", line.intercept},
                      {"ms_per_iteration_per_step", line.slope},
                      {"r2", line.r2}});
      result[robot][to_string(f)] = rows;
    }
  }
  result["linear_fits"] = fits;
  std::printf(
      "\n| robot | formulation | CPU per iteration ≈ a + b·steps: a (ms) | b (ms per step) | R² "
      "|\n");
  std::printf("|---|---|---|---|---|\n");
  for (const json& f : fits) {
    std::printf("| %s | %s | %.3f | %.5f | %.4f |\n", f["robot"].get<std::string>().c_str(),
                f["formulation"].get<std::string>().c_str(),
                kinograph::bench::json_number(f["ms_per_iteration_intercept"]),
                kinograph::bench::json_number(f["ms_per_iteration_per_step"]),
                kinograph::bench::json_number(f["r2"]));
  }
  if (!json_path.empty()) std::ofstream(json_path) << result.dump(2) << "\n";
  if (!png_path.empty()) write_plot(result, plotted_robots, plotted_formulations, png_path);
  return 0;
}

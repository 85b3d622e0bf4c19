// How soon a plan under way stops once its cancellation flag is set (what a daemon's SIGTERM
// waits for): the iiwa desk task on a fine grid planned on a thread of its own, the flag set at
// evenly spread moments of the plan, the time from setting it to the planner's graph::Cancelled.
// Prints JSON and a Markdown table.
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench/common/bench_flags.h"
#include "bench/common/bench_stats.h"
#include "kinograph/graph/cancellation.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/io/scene.h"

using namespace kinograph;
using Clock = std::chrono::steady_clock;

namespace {

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// The scene file with its `steps:` line replaced.
planning::Scene scene_with_steps(const std::string& path, int steps) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  const std::string yaml = std::regex_replace(text.str(), std::regex("(^|\n)steps: *[0-9]+"),
                                              "$1steps: " + std::to_string(steps));
  return planning::parse_scene(yaml, path);
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene_path = bench::kScenes + "iiwa_desk.yaml";
  int steps = 400, trials = 40;
  std::string json_path;
  bench::Flags flags("cancel_latency_bench");
  flags.value("--scene", &scene_path).value("--steps", &steps).value("--trials", &trials)
      .value("--json", &json_path);
  if (!flags.parse(argc, argv)) return 2;
  spdlog::set_level(spdlog::level::warn);
  const planning::Scene scene = scene_with_steps(scene_path, steps);
  const planning::BatchPlanner planner;

  const auto t_full = Clock::now();
  const planning::Plan full = planner.plan(scene.problem);
  const double full_ms = ms_since(t_full);

  std::vector<double> latencies;
  nlohmann::json runs = nlohmann::json::array();
  int finished = 0;
  for (int i = 0; i < trials; ++i) {
    const double at_ms = full_ms * (i + 0.5) / trials;
    std::atomic<bool> cancel{false};
    Clock::time_point stopped;
    bool cancelled = false;
    std::thread worker([&] {
      graph::CancellationScope scope(cancel);
      try {
        (void)planner.plan(scene.problem);
      } catch (const graph::Cancelled&) {
        cancelled = true;
      }
      stopped = Clock::now();
    });
    std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(at_ms));
    const auto t_set = Clock::now();
    cancel = true;
    worker.join();
    if (!cancelled) {
      ++finished;
      runs.push_back({{"set_at_ms", at_ms}, {"cancelled", false}});
      continue;
    }
    const double latency = std::chrono::duration<double, std::milli>(stopped - t_set).count();
    latencies.push_back(latency);
    runs.push_back({{"set_at_ms", at_ms}, {"cancelled", true}, {"latency_ms", latency}});
  }
  std::vector<double> sorted = latencies;
  std::sort(sorted.begin(), sorted.end());
  const double p90 = sorted.empty() ? std::nan("") : sorted[(sorted.size() * 9) / 10];
  int over_100 = 0;
  for (double l : latencies) over_100 += l > 100;

  nlohmann::json out{{"scene", scene_path},    {"steps", steps},
                     {"trials", trials},       {"plan_ms", full_ms},
                     {"plan_success", full.success()}, {"finished_before_flag", finished},
                     {"median_ms", bench::median(latencies)}, {"p90_ms", p90},
                     {"max_ms", bench::max_of(latencies)}, {"over_100_ms", over_100},
                     {"runs", runs}};
  std::cout << out.dump(2) << "\n\n";
  std::cout << "| scene | steps | plan (ms) | cancelled | latency median / p90 / max (ms) | over "
               "100 ms |\n|---|---|---|---|---|---|\n";
  std::cout << "| " << scene_path.substr(scene_path.rfind('/') + 1) << " | " << steps << " | "
            << bench::cell(full_ms) << " | " << latencies.size() << "/" << trials << " | "
            << bench::cell(bench::median(latencies), 1, 1) << " / " << bench::cell(p90, 1, 1)
            << " / " << bench::cell(bench::max_of(latencies), 1, 1) << " | " << over_100
            << " |\n";
  if (!json_path.empty()) std::ofstream(json_path) << out.dump(2) << "\n";
  return 0;
}

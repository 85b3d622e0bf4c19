// How long validate() takes on the shipped iiwa desk plan, and how much of it is the collision
// walk: conservative advancement along the validator's path against dense sampling of the same
// path (the sampler validate() used before). Prints JSON and a Markdown table of medians.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench/common/bench_flags.h"
#include "bench/common/bench_stats.h"
#include "kinograph/collision/collision_world.h"
#include "kinograph/collision/segment_checker.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/validate.h"

using namespace kinograph;
using bench::Flags;
using bench::median;
using Clock = std::chrono::steady_clock;

namespace {

template <typename F>
double median_ms(int reps, F&& f) {
  std::vector<double> t;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = Clock::now();
    f();
    t.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  return median(t);
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 51;
  if (!Flags("validate_bench").value("--reps", &reps).parse(argc, argv)) return 64;
  if (reps < 1) {
    std::cerr << "validate_bench: --reps must be at least 1\n";
    return 64;
  }
  spdlog::set_level(spdlog::level::warn);
  nlohmann::json out;
  std::cout << std::fixed << std::setprecision(2);
  std::cout << "| scene | validate (ms) | path walk: samples / ms | dense: samples / ms | same "
               "verdict |\n|---|---|---|---|---|\n";
  for (const std::string name : {"iiwa_desk", "iiwa_min_torque", "rr_reach"}) {
    const planning::Scene scene = planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) +
                                                       "/robots/scenes/" + name + ".yaml");
    const planning::Problem& p = scene.problem;
    const planning::Plan plan = planning::BatchPlanner().plan(p);
    const double validate_ms = median_ms(reps, [&] { (void)planning::validate(p, plan); });

    // The validator's path: its Hermite interpolation at 10 samples per interval is what
    // validate() builds; here the plan's steps joined by straight segments stand in for it
    // (the same walk either way; only the sample counts matter).
    const dynamics::Model& model = *p.model;
    dynamics::Data data(model);
    collision::CollisionWorld world(model);
    for (const auto& o : p.obstacles) (void)world.add_obstacle(o);
    collision::SegmentChecker checker(model);
    collision::PathCheckResult walk;
    const double walk_ms =
        median_ms(reps, [&] { walk = checker.check_path(world, data, plan.q, plan.t); });
    int dense_samples = 0;
    double dense_min = 0;
    const double dense_ms = median_ms(reps, [&] {
      dense_samples = 0;
      dense_min = std::numeric_limits<double>::infinity();
      for (int k = 0; k + 1 < plan.q.rows(); ++k) {
        const auto r = checker.check(world, data, plan.q.row(k).transpose(),
                                     plan.q.row(k + 1).transpose(), plan.t[k], plan.t[k + 1]);
        dense_samples += r.samples;
        dense_min = std::min(dense_min, r.min_distance);
      }
    });
    const bool same = (walk.min_distance >= 0) == (dense_min >= 0);
    out[name] = {{"plan_valid", plan.success()},           {"validate_ms", validate_ms},
                 {"walk_samples", walk.samples},           {"walk_ms", walk_ms},
                 {"walk_min_distance", walk.min_distance}, {"walk_lower_bound", walk.lower_bound},
                 {"dense_samples", dense_samples},         {"dense_ms", dense_ms},
                 {"dense_min_distance", dense_min}};
    std::cout << "| " << name << " | " << validate_ms << " | " << walk.samples << " / " << walk_ms
              << " | " << dense_samples << " / " << dense_ms << " | " << (same ? "yes" : "NO")
              << " |\n";
  }
  std::cout << out.dump(2) << "\n";
  return 0;
}

// The Acrobot swing-up under a weak elbow (robots/scenes/acrobot_swingup_4nm.yaml: ±4 N·m,
// |q̇| ≤ 6 rad/s) over several horizons and five start variants, planned three ways: straight
// from the batch planner, warm-started from the ±8 N·m plan, and by continuation in the limits.
// Prints one JSON document, then a Markdown table; see bench/robustness/README.md.
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bench/common/bench_flags.h"
#include "bench/common/bench_stats.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/io/scene.h"

namespace kinograph::bench {
namespace {

using nlohmann::json;
using planning::Plan;
using planning::Problem;

std::vector<double> parse_list(const std::string& s) {
  std::vector<double> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');) out.push_back(std::stod(item));
  return out;
}

// The problem with every finite effort and velocity limit multiplied by `scale` (model copied).
Problem with_scaled_limits(const Problem& problem, double scale) {
  Problem p = problem;
  auto model = std::make_shared<dynamics::Model>(*problem.model);
  for (dynamics::Body& b : model->bodies) {
    if (std::isfinite(b.limits.effort)) b.limits.effort *= scale;
    if (std::isfinite(b.limits.velocity)) b.limits.velocity *= scale;
  }
  p.model = std::move(model);
  return p;
}

// Continuation in the limits through the planner's API: the problem with its limits scaled by
// each of `scales` in turn, each stage warm-started from the plan before it (valid or not), the
// first from the planner's own initialization, then the problem itself from the last stage.
// `stages_valid` gets whether each stage's plan validated (against its own scaled limits).
Plan plan_with_continuation(const planning::BatchPlanner& planner, const Problem& problem,
                            const std::vector<double>& scales, std::vector<bool>& stages_valid) {
  Plan last;
  bool have_last = false;
  stages_valid.clear();
  for (double s : scales) {
    last = planner.plan(with_scaled_limits(problem, s), have_last ? &last : nullptr);
    have_last = last.q.rows() == problem.steps + 1;
    stages_valid.push_back(last.success());
  }
  return planner.plan(problem, have_last ? &last : nullptr);
}

// The horizon and steps of `p` (10 steps per second) and its start variant.
Problem variant(const Problem& base, double horizon, const Eigen::Vector2d& start) {
  Problem p = base;
  p.horizon = horizon;
  p.steps = static_cast<int>(std::lround(10 * horizon));
  p.start_q = start;
  return p;
}

struct Timed {
  Plan plan;
  double wall_s = 0;
};

template <class F>
Timed timed(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  Timed t;
  t.plan = f();
  t.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return t;
}

json record(const Timed& t) {
  const Plan& p = t.plan;
  json j = {{"success", p.success()},
            {"status", to_string(p.stats.status)},
            {"time_s", t.wall_s},
            {"iterations", p.stats.iterations}};
  if (p.q.rows() > 0) {
    j["max_elbow_torque"] = p.tau.col(1).cwiseAbs().maxCoeff();
    j["max_speed"] = p.qd.cwiseAbs().maxCoeff();
  }
  if (!p.success()) {
    j["first_failure"] = p.validation.failures.empty() ? "" : p.validation.failures[0];
  }
  return j;
}

int run(int argc, char** argv) {
  std::vector<double> horizons{8, 10, 12, 15, 20}, scales{2, 1.5, 1.25};
  std::string json_path;
  if (!Flags("acrobot_weak_bench")
           .value("--horizons", "8,10,...", [&](const std::string& s) { horizons = parse_list(s); })
           .value("--scales", "2,1.5,...", [&](const std::string& s) { scales = parse_list(s); })
           .value("--json", &json_path)
           .parse(argc, argv)) {
    return 1;
  }
  spdlog::set_level(spdlog::level::warn);
  const Problem weak = planning::load_scene(kScenes + "acrobot_swingup_4nm.yaml").problem;
  const Problem strong = planning::load_scene(kScenes + "acrobot_swingup.yaml").problem;
  const std::vector<Eigen::Vector2d> starts{{0, 0}, {0.05, 0}, {-0.05, 0}, {0, 0.05}, {0, -0.05}};
  const planning::BatchPlanner planner;
  json runs = json::array();
  std::cout << std::flush;
  for (double T : horizons) {
    for (size_t v = 0; v < starts.size(); ++v) {
      const Problem p = variant(weak, T, starts[v]);
      const Timed direct = timed([&] { return planner.plan(p); });
      const Timed warm = timed([&] {
        const Plan eight = planner.plan(variant(strong, T, starts[v]));
        return planner.plan(p, &eight);
      });
      std::vector<bool> stages;
      const Timed cont = timed([&] { return plan_with_continuation(planner, p, scales, stages); });
      json r = {{"horizon_s", T},
                {"start_q", {starts[v][0], starts[v][1]}},
                {"direct", record(direct)},
                {"warm_from_8Nm", record(warm)},
                {"continuation", record(cont)},
                {"continuation_stages_valid", stages}};
      std::cerr << r.dump() << "\n";
      runs.push_back(r);
    }
  }
  json result = {{"scene", "robots/scenes/acrobot_swingup_4nm.yaml"},
                 {"continuation_scales", scales},
                 {"steps_per_second", 10},
                 {"runs", runs}};
  std::cout << result.dump(2) << "\n\n";
  if (!json_path.empty()) std::ofstream(json_path) << result.dump(2) << "\n";
  std::cout << "| horizon (s) | method | valid | median time (s) | max time (s) | max |τ elbow| "
               "(N·m) | max |q̇| (rad/s) |\n|---|---|---|---|---|---|---|\n";
  for (double T : horizons) {
    for (const char* m : {"direct", "warm_from_8Nm", "continuation"}) {
      int ok = 0, n = 0;
      std::vector<double> times;
      double tau = 0, speed = 0;
      for (const json& r : runs) {
        if (r["horizon_s"].get<double>() != T) continue;
        ++n;
        const json& x = r[m];
        times.push_back(x["time_s"].get<double>());
        if (!x["success"].get<bool>()) continue;
        ++ok;
        tau = std::max(tau, x["max_elbow_torque"].get<double>());
        speed = std::max(speed, x["max_speed"].get<double>());
      }
      std::cout << "| " << cell(T, 1, 0) << " | " << m << " | " << ok << "/" << n << " | "
                << cell(median(times), 1, 2) << " | " << cell(max_of(times), 1, 2) << " | "
                << (ok ? cell(tau, 1, 2) : "–") << " | " << (ok ? cell(speed, 1, 2) : "–")
                << " |\n";
    }
  }
  return 0;
}

}  // namespace
}  // namespace kinograph::bench

int main(int argc, char** argv) { return kinograph::bench::run(argc, argv); }

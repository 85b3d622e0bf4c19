// The Acrobot swing-up under a weak elbow (robots/scenes/acrobot_swingup_4nm.yaml: ±4 N·m,
// |q̇| ≤ 6 rad/s) from five start variants, planned by the batch planner as it is (straight
// line, then continuation in the effort limit) and with its continuation switched off.
// Prints one JSON document, then a Markdown table; see bench/robustness/README.md.
#include <spdlog/spdlog.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bench/common/bench_flags.h"
#include "bench/common/bench_stats.h"
#include "bench/common/between_knots_measure.h"
#include "bench/common/timed_plan.h"
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

json record(const Problem& p, const Run& r) {
  const Plan& plan = r.plan;
  json j = {{"success", plan.success()},
            {"status", to_string(plan.stats.status)},
            {"time_s", r.wall_s},
            {"iterations", plan.stats.iterations},
            {"attempts", plan.stats.attempts}};
  if (plan.q.rows() == p.steps + 1) {
    const BetweenKnots m = measure_between_knots(*p.model, plan, 10);
    j["between_knots_shoulder_torque"] = m.shoulder;
    j["between_knots_elbow_peak"] = m.elbow_max;
    j["validator_shoulder_torque_between"] = plan.validation.max_unactuated_torque_between;
    j["max_speed"] = plan.qd.cwiseAbs().maxCoeff();
  }
  if (!plan.success()) {
    j["first_failure"] = plan.validation.failures.empty() ? "" : plan.validation.failures[0];
    j["reason"] = plan.stats.reason;
  }
  return j;
}

std::string start_name(const Eigen::Vector2d& q) {
  std::ostringstream os;
  os << "(" << q[0] << ", " << q[1] << ")";
  return os.str();
}

int run(int argc, char** argv) {
  std::vector<double> horizons{40};
  double per_second = 10;
  bool direct = true;
  std::string json_path;
  if (!Flags("acrobot_weak_bench")
           .value("--horizons", "40,...", [&](const std::string& s) { horizons = parse_list(s); })
           .value("--steps-per-second", &per_second)
           .toggle("--no-direct", [&] { direct = false; })
           .value("--json", &json_path)
           .parse(argc, argv)) {
    return 1;
  }
  spdlog::set_level(spdlog::level::err);
  const Problem weak = planning::load_scene(kScenes + "acrobot_swingup_4nm.yaml").problem;
  const std::vector<Eigen::Vector2d> starts{{0, 0}, {0.05, 0}, {-0.05, 0}, {0, 0.05}, {0, -0.05}};
  const planning::BatchPlanner planner;
  planning::BatchPlannerOptions off;
  off.effort_continuation.clear();
  const planning::BatchPlanner without(off);
  json runs = json::array();
  for (double T : horizons) {
    for (const Eigen::Vector2d& start : starts) {
      Problem p = weak;
      p.horizon = T;
      p.steps = static_cast<int>(std::lround(per_second * T));
      p.start_q = start;
      json r = {{"horizon_s", T},
                {"steps", p.steps},
                {"start_q", {start[0], start[1]}},
                {"planner", record(p, plan_once(planner, p))}};
      if (direct) r["without_continuation"] = record(p, plan_once(without, p));
      std::cerr << r.dump() << "\n";
      runs.push_back(r);
    }
  }
  json result = {{"scene", "robots/scenes/acrobot_swingup_4nm.yaml"},
                 {"effort_continuation", planning::BatchPlannerOptions().effort_continuation},
                 {"runs", runs}};
  std::cout << result.dump(2) << "\n\n";
  if (!json_path.empty()) std::ofstream(json_path) << result.dump(2) << "\n";
  std::cout << "| start q (rad) | horizon (s) | steps | planner | valid | time (s) | iterations | "
               "max between-knot shoulder τ (N·m) | elbow peak (N·m) |\n"
               "|---|---|---|---|---|---|---|---|---|\n";
  for (const json& r : runs) {
    for (const char* m : {"planner", "without_continuation"}) {
      if (!r.contains(m)) continue;
      const json& x = r[m];
      const bool ok = x["success"].get<bool>();
      const Eigen::Vector2d start(r["start_q"][0].get<double>(), r["start_q"][1].get<double>());
      std::cout << "| " << start_name(start) << " | " << cell(r["horizon_s"].get<double>(), 1, 0)
                << " | " << r["steps"].get<int>() << " | "
                << (std::string(m) == "planner" ? "as it is" : "no continuation") << " | "
                << (ok ? "yes" : "no") << " | " << cell(x["time_s"].get<double>(), 1, 1) << " | "
                << x["iterations"].get<int>() << " | "
                << (ok ? cell(x["between_knots_shoulder_torque"].get<double>(), 1, 4) : "–")
                << " | " << (ok ? cell(x["between_knots_elbow_peak"].get<double>(), 1, 2) : "–")
                << " |\n";
    }
  }
  return 0;
}

}  // namespace
}  // namespace kinograph::bench

int main(int argc, char** argv) { return kinograph::bench::run(argc, argv); }

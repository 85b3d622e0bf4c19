// Planning benchmarks of the paper's Table I on this machine: the Acrobot swing-up, and the
// iiwa's task 1 (block from under the desk to 50 seeded goals) and task 2 (the same with the
// minimum-torque objective, compared with the same goals planned without it). Prints one JSON
// document, then a Markdown table; see bench/planning/README.md.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numeric>
#include <string>
#include <vector>

#include "bench/common/bench_flags.h"
#include "bench/common/bench_stats.h"
#include "bench/common/iiwa_goals.h"
#include "bench/common/timed_plan.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/goal_sampler.h"
#include "kinograph/planning/io/plan_json.h"
#include "kinograph/planning/io/scene.h"

namespace kinograph::bench {
namespace {

using nlohmann::json;
using planning::Plan;
using planning::Problem;

// The paper's "total torque" of a run (N·m): Σ_k Σ_j |τ_kj| over every state and joint.
double total_torque(const Plan& plan) { return plan.tau.cwiseAbs().sum(); }

// The median over the successful runs of each part of SolveTimes (ms): where a typical valid
// plan's time goes.
json median_parts_ms(const std::vector<Run>& runs) {
  const std::vector<std::pair<const char*, double planning::SolveTimes::*>> parts = {
      {"initialization", &planning::SolveTimes::initialization_s},
      {"graph_building", &planning::SolveTimes::graph_building_s},
      {"linearization", &planning::SolveTimes::linearization_s},
      {"factorization", &planning::SolveTimes::factorization_s},
      {"triangular_solve", &planning::SolveTimes::triangular_solve_s},
      {"multipliers", &planning::SolveTimes::multipliers_s},
      {"between_knot_checks", &planning::SolveTimes::between_knot_checks_s},
      {"validation", &planning::SolveTimes::validation_s}};
  json out = json::object();
  for (const auto& [name, part] : parts) {
    std::vector<double> ms;
    for (const Run& r : runs) {
      if (r.plan.success()) ms.push_back(1e3 * (r.plan.stats.times.*part));
    }
    out[name] = median(ms);
  }
  return out;
}

// Success rate and times of a set of runs (times over successful runs, as the paper).
json summary(const std::vector<Run>& runs) {
  std::vector<double> ok_times, all_times, iterations, objectives;
  std::vector<bool> valid;
  int ok = 0;
  for (const Run& r : runs) {
    all_times.push_back(r.wall_s);
    objectives.push_back(r.plan.stats.cost);
    valid.push_back(r.plan.success());
    iterations.push_back(r.plan.stats.iterations);
    if (r.plan.success()) {
      ++ok;
      ok_times.push_back(r.wall_s);
    }
  }
  return {{"runs", runs.size()},
          {"successes", ok},
          {"success_rate", runs.empty() ? 0.0 : double(ok) / runs.size()},
          {"time_s_median", median(ok_times)},
          {"time_s_mean", mean(ok_times)},
          {"time_s_max", max_of(ok_times)},
          {"time_s_median_all", median(all_times)},
          {"time_s_mean_all", mean(all_times)},  // failures included: a user waits for those too
          {"time_s_max_all", max_of(all_times)},
          {"iterations_median", median(iterations)},
          {"time_parts_ms_median", median_parts_ms(runs)},
          {"valid_all", valid},            // per run, in run order
          {"time_s_all", all_times},       // per run: wall time
          {"iterations_all", iterations},  // per run: LM iterations
          {"objective_all", objectives}};  // per run: the plan's soft cost
}

json failures_of(const std::vector<Run>& runs) {
  json out = json::array();
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (runs[i].plan.success()) continue;
    const Plan& p = runs[i].plan;
    out.push_back({{"goal", i},
                   {"status", to_string(p.stats.status)},
                   {"first_failure",
                    p.validation.failures.empty() ? std::string() : p.validation.failures[0]}});
  }
  return out;
}

int run(int argc, char** argv) {
  int goals = 50, acrobot_repeats = 5;
  std::string json_path;
  if (!Flags("planning_bench")
           .value("--goals", &goals)
           .value("--acrobot-repeats", &acrobot_repeats)
           .value("--json", &json_path)
           .parse(argc, argv)) {
    return 1;
  }
  // Every table row and the Acrobot's torques come from at least one run.
  if (goals < 1 || acrobot_repeats < 1) {
    std::cerr << "planning_bench: --goals and --acrobot-repeats must be at least 1\n";
    return 1;
  }
  spdlog::set_level(spdlog::level::warn);
  const planning::BatchPlanner planner;
  json result;

  // Acrobot swing-up: the same problem repeated; the median time.
  {
    const planning::Scene scene = planning::load_scene(kScenes + "acrobot_swingup.yaml");
    std::vector<Run> runs;
    for (int i = 0; i < acrobot_repeats; ++i) runs.push_back(plan_once(planner, scene.problem));
    json s = summary(runs);
    const Plan& p = runs.front().plan;
    s["max_unactuated_torque"] = p.validation.max_unactuated_torque;
    s["max_elbow_torque"] = p.tau.col(1).cwiseAbs().maxCoeff();
    s["goal_error"] = p.validation.goal_error;
    s["status"] = to_string(p.stats.status);
    s["failures"] = p.validation.failures;
    result["acrobot"] = s;
    std::cerr << "acrobot: " << s.dump() << "\n";
  }

  // iiwa task 1: start under the desk, 50 seeded goals.
  const planning::Scene desk = planning::load_scene(kScenes + "iiwa_desk.yaml");
  {
    planning::GoalSampler sampler(desk.problem, iiwa_goal_options(1));
    const std::vector<Eigen::VectorXd> targets = sampler.sample(goals);
    std::vector<Run> runs;
    for (const Eigen::VectorXd& q : targets) {
      Problem problem = desk.problem;
      problem.goal.q = q;
      runs.push_back(plan_once(planner, problem));
    }
    json s = summary(runs);
    s["goal_candidates_drawn"] = sampler.attempts();
    s["failed"] = failures_of(runs);
    result["iiwa_task1"] = s;
    std::cerr << "iiwa task 1: " << s.dump() << "\n";
  }

  // iiwa task 2: the same kind of goals (another seed), each planned with and without the
  // minimum-torque objective.
  {
    const planning::Scene task2 = planning::load_scene(kScenes + "iiwa_min_torque.yaml");
    planning::GoalSampler sampler(task2.problem, iiwa_goal_options(2));
    const std::vector<Eigen::VectorXd> targets = sampler.sample(goals);
    std::vector<Run> with, without;
    std::vector<double> torque_with, torque_without, impulse_with, impulse_without;
    int lower = 0, paper_success = 0;
    for (const Eigen::VectorXd& q : targets) {
      Problem problem = task2.problem;
      problem.goal.q = q;
      with.push_back(plan_once(planner, problem));
      problem.objectives.min_torque = 0;
      without.push_back(plan_once(planner, problem));
      const Plan &a = with.back().plan, &b = without.back().plan;
      if (a.success() && b.success()) {
        const double dt = problem.dt();
        torque_with.push_back(total_torque(a));
        torque_without.push_back(total_torque(b));
        impulse_with.push_back(total_torque(a) * dt);
        impulse_without.push_back(total_torque(b) * dt);
        if (torque_with.back() < torque_without.back()) ++lower;
      }
      // The paper's task-2 success: valid and less total torque than without the objective.
      if (a.success() && (!b.success() || total_torque(a) < total_torque(b))) ++paper_success;
    }
    json s = summary(with);
    s["goal_candidates_drawn"] = sampler.attempts();
    s["min_torque_weight"] = task2.problem.objectives.min_torque;
    s["paper_success_rate"] = with.empty() ? 0.0 : double(paper_success) / with.size();
    s["without_min_torque"] = summary(without);
    s["both_valid"] = torque_with.size();
    s["lower_torque_with_objective"] = lower;
    s["total_torque_with_mean"] = mean(torque_with);
    s["total_torque_without_mean"] = mean(torque_without);
    s["torque_impulse_with_mean"] = mean(impulse_with);
    s["torque_impulse_without_mean"] = mean(impulse_without);
    s["failed"] = failures_of(with);
    result["iiwa_task2"] = s;
    std::cerr << "iiwa task 2: " << s.dump() << "\n";
  }

  result["settings"] = {{"goals", goals},
                        {"acrobot_repeats", acrobot_repeats},
                        {"total_torque", "sum over states k and joints j of |tau_kj| (N·m)"},
                        {"torque_impulse", "total_torque * dt (N·m·s)"},
                        {"time", "wall time of BatchPlanner::plan (build, solve, validate)"}};
  std::cout << result.dump(2) << "\n\n";
  if (!json_path.empty()) std::ofstream(json_path) << result.dump(2) << "\n";

  const json &ac = result["acrobot"], &t1 = result["iiwa_task1"], &t2 = result["iiwa_task2"];
  std::cout << "| problem | success | median time (ms) | mean (ms) | max (ms) | paper success | "
               "paper mean time | target median |\n";
  std::cout << "|---|---|---|---|---|---|---|---|\n";
  const auto row = [&](const char* name, const json& s, const char* paper_rate,
                       const char* paper_time, const char* target) {
    std::cout << "| " << name << " | " << s["successes"].get<int>() << "/" << s["runs"].get<int>()
              << " | " << cell(s["time_s_median"].get<double>(), 1e3) << " | "
              << cell(s["time_s_mean"].get<double>(), 1e3) << " | "
              << cell(s["time_s_max"].get<double>(), 1e3) << " | " << paper_rate << " | "
              << paper_time << " | " << target << " |\n";
  };
  const auto num = [](const json& v) { return v.is_number() ? v.get<double>() : std::nan(""); };
  row("Acrobot swing-up", ac, "100 %", "1.07 s", "≤ 100 ms");
  row("iiwa task 1 (desk)", t1, "86 %", "2.15 s", "≤ 300 ms");
  row("iiwa task 2 (min torque)", t2, "90 %", "1.75 s", "≤ 300 ms");
  row("iiwa task 2 without min torque", t2["without_min_torque"], "–", "–", "–");
  std::cout << "\nTask 2 total torque Σ_k Σ_j |τ_kj| over goals where both plans validate ("
            << t2["both_valid"].get<std::size_t>() << "): with min torque "
            << cell(num(t2["total_torque_with_mean"]), 1, 1) << " N·m, without "
            << cell(num(t2["total_torque_without_mean"]), 1, 1)
            << " N·m (paper: 1522 vs 1748 N·m); lower with the objective on "
            << t2["lower_torque_with_objective"].get<int>() << " goals; paper-style success "
            << cell(num(t2["paper_success_rate"]), 100, 0) << " %.\n";
  return 0;
}

}  // namespace
}  // namespace kinograph::bench

int main(int argc, char** argv) { return kinograph::bench::run(argc, argv); }

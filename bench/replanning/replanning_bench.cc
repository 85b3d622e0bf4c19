// Replanning benchmark of the paper's Table II on this machine: for each iiwa problem
// of tasks 1 and 2 (robots/scenes/iiwa_desk.yaml, iiwa_min_torque.yaml; first goals from the
// seeded goal sampler, as bench/planning), plan once, change the goal to a nearby seeded random
// goal and replan with DFGP-L (batch, straight line), DFGP-W (batch, warm start from the first
// plan) and iDFGP (IncrementalPlanner::set_goal). Also an obstacle-move row: the desk top
// shifted by a seeded random offset, and a row of goal changes in a row, each from the answer
// to the last. Prints one JSON document, then a Markdown table; see bench/replanning/README.md.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "bench/common/bench_flags.h"
#include "bench/common/bench_stats.h"
#include "bench/common/iiwa_goals.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/goal_sampler.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/replanner.h"

namespace kinograph::bench {
namespace {

using nlohmann::json;
using planning::Plan;
using planning::Problem;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// One method's runs on a set of replanning problems.
struct Method {
  std::vector<double> ok_times, all_times, torque, cost;
  std::vector<double> all_cost;  // per run, NaN where the plan failed
  int runs = 0, ok = 0;
  int incremental_ok = 0;  // iDFGP: validated without the batch fallback
  int fell_back = 0;
  int retried = 0;  // iDFGP: the warm fallback failed too and a plan from scratch was made
  std::vector<double> updates;

  void add(const Plan& plan, double wall_s) {
    ++runs;
    all_times.push_back(wall_s);
    all_cost.push_back(plan.success() ? plan.stats.cost : std::nan(""));
    if (plan.success()) {
      ++ok;
      ok_times.push_back(wall_s);
      torque.push_back(plan.tau.cwiseAbs().sum());
      cost.push_back(plan.stats.cost);
    }
  }
  json to_json() const {
    json j = {{"runs", runs},
              {"successes", ok},
              {"success_rate", runs ? double(ok) / runs : 0.0},
              {"time_s_mean", mean(ok_times)},
              {"time_s_median", median(ok_times)},
              {"time_s_max", max_of(ok_times)},
              {"time_s_median_all", median(all_times)},
              {"time_s_mean_all", mean(all_times)},
              {"total_torque_mean", mean(torque)},
              {"objective_mean", mean(cost)},
              {"time_s_all", all_times},
              {"objective_all", all_cost}};
    if (!updates.empty()) {
      j["incremental_successes"] = incremental_ok;
      j["fell_back"] = fell_back;
      j["retried_from_scratch"] = retried;
      j["isam2_updates_median"] = median(updates);
      j["isam2_updates"] = updates;  // per run, in run order (with time_s_all)
    }
    return j;
  }
};

struct Row {
  Method L, W, inc;
  int problems = 0, first_failed = 0, no_change = 0;
  std::vector<double> first_cost;  // per first plan: its soft cost, NaN where it failed
  std::vector<double> prepare;     // per first plan: Replanner::prepare's wall time [s]
  std::vector<double> first_s;     // per first plan: its wall time [s], failed ones included
};

json row_json(const Row& r) {
  return {{"problems", r.problems},
          {"first_plan_failed", r.first_failed},
          {"first_plan_objective_all", r.first_cost},
          {"first_plan_s_all", r.first_s},
          {"first_plan_s_median", median(r.first_s)},
          {"prepare_s_median", median(r.prepare)},
          {"no_nearby_change", r.no_change},
          {"DFGP-L", r.L.to_json()},
          {"DFGP-W", r.W.to_json()},
          {"iDFGP", r.inc.to_json()}};
}

// Plans `problem` as the first plan of a row's problem; empty (and counted) when it fails.
std::optional<Plan> first_plan(Row& row, planning::Replanner& planner, const Problem& problem) {
  ++row.problems;
  const auto t0 = std::chrono::steady_clock::now();
  Plan first = planner.plan(problem, /*new_goal=*/true);
  row.first_s.push_back(
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  row.first_cost.push_back(first.success() ? first.stats.cost : std::nan(""));
  if (!first.success()) {
    ++row.first_failed;
    return std::nullopt;
  }
  return first;
}

// Adds an iDFGP replan and what the replanner reports of it to `inc`.
void add_replan(Method& inc, const Plan& plan, double wall_s, const planning::ReplanReport& r) {
  inc.add(plan, wall_s);
  inc.updates.push_back(r.statistics.updates);
  if (r.fell_back) ++inc.fell_back;
  if (r.retried_from_scratch) ++inc.retried;
  if (plan.success() && r.incremental && !r.fell_back) ++inc.incremental_ok;
}

// Plans `first`, and replans `changed` with all three methods: at the first plan's start
// (iDFGP applies `change`), or, with `knots` > 0, after the robot went on that many knots along
// it (DFGP-W from the motion gone on, iDFGP on the tree shifted there).
void replan_all(Row& row, const Problem& first_problem, Problem changed,
                const planning::ProblemChange& change, const planning::ReplannerOptions& ro,
                int knots = 0) {
  planning::Replanner planner(ro);
  const std::optional<Plan> planned = first_plan(row, planner, first_problem);
  if (!planned) return;
  const Plan& first = *planned;
  // As a daemon does while it waits for the next change.
  row.prepare.push_back(planner.prepare());
  const Plan warm = knots > 0 ? planning::gone_on(first, knots) : first;
  if (knots > 0) {
    changed.start_q = warm.q.row(0).transpose();
    changed.start_qd = warm.qd.row(0).transpose();
  }
  const planning::BatchPlanner batch(ro.incremental.batch);
  auto t0 = Clock::now();
  const Plan l = batch.plan(changed);
  row.L.add(l, seconds_since(t0));
  t0 = Clock::now();
  const Plan w = batch.plan(changed, &warm);
  row.W.add(w, seconds_since(t0));
  t0 = Clock::now();
  const Plan inc = knots > 0 ? planner.plan(changed, /*new_goal=*/false, &warm, knots)
                             : planner.replan(change);
  add_replan(row.inc, inc, seconds_since(t0), planner.last_report());
}

// Plans `first_problem`, then changes its goal `length` times in a row, each a nearby goal of
// the last, as a daemon is asked while the robot waits: DFGP-W warm-starts from its own last
// answer, iDFGP replans on one Replanner (prepared before each change). DFGP-L is not run.
void replan_sequence(Row& row, const Problem& first_problem, planning::GoalSampler& sampler,
                     double radius, int length, uint64_t seed,
                     const planning::ReplannerOptions& ro) {
  planning::Replanner planner(ro);
  const std::optional<Plan> first = first_plan(row, planner, first_problem);
  if (!first) return;
  const planning::BatchPlanner batch(ro.incremental.batch);
  Plan last_w = *first;
  Eigen::VectorXd goal = first_problem.goal.q;
  for (int k = 0; k < length; ++k) {
    const auto next = nearby_goal(sampler, goal, radius, seed + k);
    if (!next) {
      ++row.no_change;
      continue;
    }
    goal = *next;
    planning::ProblemChange change;
    change.goal = first_problem.goal;
    change.goal->q = goal;
    Problem changed = first_problem;
    changed.goal = *change.goal;
    row.prepare.push_back(planner.prepare());
    auto t0 = Clock::now();
    const Plan w = batch.plan(changed, &last_w);
    row.W.add(w, seconds_since(t0));
    if (w.success()) last_w = w;
    t0 = Clock::now();
    const Plan inc = planner.replan(change);
    add_replan(row.inc, inc, seconds_since(t0), planner.last_report());
  }
}

int run(int argc, char** argv) {
  int problems = 50, obstacle_problems = -1, knots = 5;
  int sequence_problems = -1, sequence_length = 5;
  double radius = 0.2, shift = 0.05;
  double limit_epsilon = -1;  // < 0: the scenes' own
  int only = -1;              // >= 0: replan only this problem of each row (debugging)
  std::string json_path;
  spdlog::level::level_enum log_level = spdlog::level::warn;
  // iDFGP as the daemon replans: the incremental replan, the warm-started batch solve when it
  // does not validate, and a plan from scratch when that does not either
  // (--no-retry-from-scratch: only the first two).
  planning::ReplannerOptions ro;
  planning::IncrementalPlannerOptions& io = ro.incremental;
  if (!Flags("replanning_bench")
           .value("--problems", &problems)
           .value("--obstacle-problems", &obstacle_problems)
           .value("--radius", &radius)
           .value("--shift", &shift)
           .value("--gone-on", &knots)
           .value("--sequence-problems", &sequence_problems)
           .value("--sequence-length", &sequence_length)
           .value("--json", &json_path)
           .value("--log-level", "warn|info|debug|trace",
                  [&](const std::string& v) { log_level = spdlog::level::from_str(v); })
           .toggle("--no-retry-from-scratch", [&] { ro.retry_from_scratch = false; })
           .toggle("--polish-objective", [&] { io.stop_at_first_valid = false; })
           .toggle("--linearize-at-evaluation",
                   [&] { io.isam2.linearize_at_evaluation = true; })
           .value("--lambda-initial", &io.isam2.lambda_initial)
           .value("--lambda-decrease", &io.isam2.lambda_decrease)
           .value("--lambda-min", &io.isam2.lambda_min)
           .value("--limit-epsilon", &limit_epsilon)
           .value("--only", &only)
           .parse(argc, argv)) {
    return 1;
  }
  if (obstacle_problems < 0) obstacle_problems = problems;
  if (sequence_problems < 0) sequence_problems = obstacle_problems;
  spdlog::set_level(log_level);
  json result;

  const char* tasks[2][2] = {{"task1", "iiwa_desk.yaml"}, {"task2", "iiwa_min_torque.yaml"}};
  std::vector<Row> rows(2);
  for (int t = 0; t < 2; ++t) {
    planning::Scene scene = planning::load_scene(kScenes + tasks[t][1]);
    if (limit_epsilon >= 0) scene.problem.objectives.limit_epsilon = limit_epsilon;
    planning::GoalSampler sampler(scene.problem, iiwa_goal_options(t + 1));
    const std::vector<Eigen::VectorXd> goals = sampler.sample(problems);
    Row& row = rows[t];
    for (size_t i = 0; i < goals.size(); ++i) {
      if (only >= 0 && static_cast<int>(i) != only) continue;
      Problem first = scene.problem;
      first.goal.q = goals[i];
      const auto next = nearby_goal(sampler, goals[i], radius, 1000 * (t + 1) + i);
      if (!next) {
        ++row.no_change;
        continue;
      }
      planning::ProblemChange change;
      change.goal = first.goal;
      change.goal->q = *next;
      Problem changed = first;
      changed.goal = *change.goal;
      replan_all(row, first, changed, change, ro);
      std::cerr << tasks[t][0] << " " << i << ": L " << row.L.ok << " W " << row.W.ok << " iDFGP "
                << row.inc.ok << " / " << row.L.runs << "\n";
    }
    result[tasks[t][0]] = row_json(row);
  }

  // Obstacle move (task 1's scene and goals): the desk top shifted by up to ±shift in x, y, z.
  Row moved, gone;  // the desk moved at the start, and after the robot went on `knots` knots
  {
    planning::Scene scene = planning::load_scene(kScenes + "iiwa_desk.yaml");
    if (limit_epsilon >= 0) scene.problem.objectives.limit_epsilon = limit_epsilon;
    planning::GoalSampler sampler(scene.problem, iiwa_goal_options(1));
    const std::vector<Eigen::VectorXd> goals = sampler.sample(obstacle_problems);
    const int top = 0;  // desk_top, the scene's first obstacle
    for (size_t i = 0; i < goals.size(); ++i) {
      if (only >= 0 && static_cast<int>(i) != only) continue;
      Problem first = scene.problem;
      first.goal.q = goals[i];
      std::mt19937_64 rng(5000 + i);
      std::uniform_real_distribution<double> u(-shift, shift);
      collision::Obstacle o = first.obstacles[top];
      bool ok = false;
      Problem changed = first;
      for (int tries = 0; tries < 100 && !ok; ++tries) {
        o.pose = first.obstacles[top].pose;
        o.pose.translation() += Eigen::Vector3d(u(rng), u(rng), u(rng));
        changed.obstacles[top] = o;
        ok = planning::check_problem(changed).empty();
      }
      if (!ok) {
        ++moved.no_change;
        continue;
      }
      planning::ProblemChange change;
      change.add_or_move.push_back(o);
      replan_all(moved, first, changed, change, ro);
      replan_all(gone, first, changed, change, ro, knots);
      std::cerr << "obstacle move " << i << ": L " << moved.L.ok << " W " << moved.W.ok << " iDFGP "
                << moved.inc.ok << " / " << moved.L.runs << "\n";
    }
    result["obstacle_move"] = row_json(moved);
    result["gone_on_obstacle_move"] = row_json(gone);
  }

  // Goal changes in a row (task 1's scene and first goals).
  Row sequence;
  {
    const planning::Scene scene = planning::load_scene(kScenes + "iiwa_desk.yaml");
    Problem base = scene.problem;
    if (limit_epsilon >= 0) base.objectives.limit_epsilon = limit_epsilon;
    planning::GoalSampler sampler(base, iiwa_goal_options(1));
    const std::vector<Eigen::VectorXd> goals = sampler.sample(sequence_problems);
    for (size_t i = 0; i < goals.size(); ++i) {
      if (only >= 0 && static_cast<int>(i) != only) continue;
      Problem first = base;
      first.goal.q = goals[i];
      replan_sequence(sequence, first, sampler, radius, sequence_length, 3000 + 100 * i, ro);
      std::cerr << "goal sequence " << i << ": W " << sequence.W.ok << " iDFGP " << sequence.inc.ok
                << " / " << sequence.W.runs << "\n";
    }
    result["goal_sequence"] = row_json(sequence);
  }
  result["settings"] = {
      {"problems", problems},
      {"obstacle_problems", obstacle_problems},
      {"goal_change_radius_rad", radius},
      {"desk_shift_m", shift},
      {"gone_on_knots", knots},
      {"sequence_problems", sequence_problems},
      {"sequence_length", sequence_length},
      {"retry_from_scratch", ro.retry_from_scratch},
      {"time", "wall time of the replanning call (build, solve, validate, fallback, retry)"},
      {"success", "the plan validates (planning::validate)"},
      {"total_torque", "sum over states and joints of |tau| (N·m), mean over successes"}};
  std::cout << result.dump(2) << "\n\n";
  if (!json_path.empty()) std::ofstream(json_path) << result.dump(2) << "\n";

  std::cout << "| test | method | success | mean time (ms) | median (ms) | max (ms) | mean total "
               "torque (N·m) | paper success | paper mean / max time |\n";
  std::cout << "|---|---|---|---|---|---|---|---|---|\n";
  constexpr int kRows = 5;
  const char* paper[kRows][3] = {{"86 %", "92 %", "80 %"},
                                 {"90 %", "98 %", "96 %"},
                                 {"–", "–", "–"},
                                 {"–", "–", "–"},
                                 {"–", "–", "–"}};
  const char* paper_t[kRows][3] = {{"1.98 / 3.33 s", "1.12 / 3.09 s", "0.119 / 0.200 s"},
                                   {"1.68 / 2.98 s", "0.63 / 1.76 s", "0.074 / 0.078 s"},
                                   {"–", "–", "–"},
                                   {"–", "–", "–"},
                                   {"–", "–", "–"}};
  const std::string gone_name =
      "task 1 desk moved, " + std::to_string(knots) + " knots on";
  const std::string sequence_name =
      "task 1 goal changes in a row (" + std::to_string(sequence_length) + " each)";
  const char* names[kRows] = {"task 1 goal change", "task 2 goal change", "task 1 desk moved",
                              gone_name.c_str(), sequence_name.c_str()};
  const Row* all[kRows] = {&rows[0], &rows[1], &moved, &gone, &sequence};
  for (int r = 0; r < kRows; ++r) {
    const Method* ms[3] = {&all[r]->L, &all[r]->W, &all[r]->inc};
    const char* mn[3] = {"DFGP-L", "DFGP-W", "iDFGP"};
    for (int m = 0; m < 3; ++m) {
      const Method& x = *ms[m];
      if (x.runs == 0) continue;  // not run in this row (DFGP-L in the goal sequence)
      std::cout << "| " << names[r] << " | " << mn[m] << " | " << x.ok << "/" << x.runs << " ("
                << cell(x.runs ? double(x.ok) / x.runs : std::nan(""), 100) << " %) | "
                << cell(mean(x.ok_times), 1e3, 1) << " | " << cell(median(x.ok_times), 1e3, 1)
                << " | " << cell(max_of(x.ok_times), 1e3, 1) << " | " << cell(mean(x.torque), 1, 0)
                << " | " << paper[r][m] << " | " << paper_t[r][m] << " |\n";
    }
  }
  for (int r = 0; r < kRows; ++r) {
    const Method& x = all[r]->inc;
    std::cout << "\n"
              << names[r] << ": " << all[r]->problems << " problems, " << all[r]->first_failed
              << " first plans did not validate (not replanned); iDFGP " << x.incremental_ok
              << " validated incrementally, " << x.fell_back
              << " fell back to a warm batch solve, " << x.retried
              << " of them then planned from scratch; median " << cell(median(x.updates))
              << " ISAM2 updates; speed-up of iDFGP over DFGP-W (mean times) "
              << cell(mean(all[r]->W.ok_times) / mean(x.ok_times), 1, 1) << "×, median "
              << cell(median(all[r]->W.ok_times) / median(x.ok_times), 1, 1) << "×.";
  }
  std::cout << "\n";
  return 0;
}

}  // namespace
}  // namespace kinograph::bench

int main(int argc, char** argv) { return kinograph::bench::run(argc, argv); }

// Robust solving on the iiwa desk: seeded random starts under the desk (to the scene's goal) and
// seeded random goals above it (from the scene's start), every problem feasible by the checks
// that can prove it (check_problem: limits, start and goal clear of the desk, the floor and the
// robot's own links, a horizon the motion bounds allow), each planned by the batch planner as it
// is and, interleaved, with its path search off. Prints one JSON document, then Markdown tables;
// see bench/robustness/README.md.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench/common/bench_flags.h"
#include "bench/common/bench_stats.h"
#include "bench/common/clearance_walk.h"
#include "bench/common/iiwa_goals.h"
#include "bench/common/timed_plan.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/goal_sampler.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/motion_bounds.h"
#include "kinograph/planning/problem_check.h"

namespace kinograph::bench {
namespace {

using nlohmann::json;
using planning::Plan;
using planning::Problem;

constexpr int kWalkSamples = 40;  // points per interval of the benchmark's own clearance walk

// The horizon of a move: twice the least time its slowest joint needs alone at its velocity and
// acceleration limits (motion_bounds; the joints share one motion and must go around the desk),
// at least the scene's 3 s, rounded up to 0.1 s; 10 steps per second as the scene.
void fit_horizon(Problem& p) {
  double t = 0;
  for (int j = 0; j < p.model->nq(); ++j) {
    const dynamics::JointLimits& l = p.model->bodies[j].limits;
    t = std::max(
        t, planning::min_time_to_rest(p.goal.q[j] - p.start_q[j], 0, l.velocity, l.acceleration));
  }
  p.horizon = std::max(3.0, std::ceil(2 * t * 10 - 1e-9) / 10);
  p.steps = static_cast<int>(std::lround(10 * p.horizon));
}

// One kind of random problem: `count` feasible problems, drawing configurations from `sampler`
// for the start (random_start) or the goal, skipping any that check_problem refuses.
struct Drawn {
  std::vector<Problem> problems;
  int refused = 0;
  std::map<std::string, int> refusals;  // check_problem's reason → count
};

Drawn draw(const Problem& scene, planning::GoalSampler& sampler, bool random_start, int count) {
  Drawn d;
  while (static_cast<int>(d.problems.size()) < count) {
    const std::optional<Eigen::VectorXd> q = sampler.sample();
    if (!q) break;
    Problem p = scene;
    (random_start ? p.start_q : p.goal.q) = *q;
    fit_horizon(p);
    const std::string why = planning::check_problem(p);
    if (!why.empty()) {
      ++d.refused;
      ++d.refusals[why.substr(0, why.find(':'))];
      continue;
    }
    d.problems.push_back(std::move(p));
  }
  return d;
}

std::vector<double> as_vector(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

struct Tally {
  int ok = 0, clear = 0;
  double worst_self = std::numeric_limits<double>::infinity();
  double worst_floor = std::numeric_limits<double>::infinity();
  std::vector<double> ok_times, all_times;
  std::map<std::string, int> reasons;  // first validation failure of each failed plan, by kind

  json summary(std::size_t runs) const {
    return {{"runs", runs},
            {"successes", ok},
            {"successes_clear", clear},
            {"min_self_clearance_m", worst_self},
            {"min_floor_clearance_m", worst_floor},
            {"time_s_median", median(ok_times)},
            {"time_s_max", max_of(ok_times)},
            {"time_s_median_all", median(all_times)},
            {"time_s_max_all", max_of(all_times)},
            {"failure_kinds", reasons}};
  }
};

// The kind of a failure: the validator's first failed check up to its first number.
std::string kind_of(const Plan& plan) {
  if (plan.validation.failures.empty()) return "unknown";
  const std::string& f = plan.validation.failures[0];
  const std::size_t cut = f.find_first_of("0123456789-");
  return f.substr(0, cut == std::string::npos ? f.size() : cut);
}

json plan_case(const Problem& p, const Run& r, Tally& t) {
  t.all_times.push_back(r.wall_s);
  json c = {{"success", r.plan.success()},
            {"status", to_string(r.plan.stats.status)},
            {"attempts", r.plan.stats.attempts},
            {"time_s", r.wall_s}};
  if (r.plan.success()) {
    ++t.ok;
    t.ok_times.push_back(r.wall_s);
    const Clearance cl = clearance_walk(p, r.plan, kWalkSamples);
    t.worst_self = std::min(t.worst_self, cl.self);
    t.worst_floor = std::min(t.worst_floor, cl.floor);
    if (cl.self >= 0 && cl.floor >= 0) ++t.clear;
    c["self_clearance_m"] = cl.self;
    c["floor_clearance_m"] = cl.floor;
  } else {
    ++t.reasons[kind_of(r.plan)];
    c["reason"] = r.plan.stats.reason;
    c["first_failure"] =
        r.plan.validation.failures.empty() ? std::string() : r.plan.validation.failures[0];
  }
  return c;
}

int run(int argc, char** argv) {
  int count = 50;
  std::string json_path;
  if (!Flags("robustness_bench")
           .value("--count", &count)
           .value("--json", &json_path)
           .parse(argc, argv)) {
    return 1;
  }
  spdlog::set_level(spdlog::level::warn);
  const planning::Scene desk = planning::load_scene(kScenes + "iiwa_desk.yaml");
  const planning::BatchPlanner planner;
  planning::BatchPlannerOptions no_search_options;
  no_search_options.path_search.max_samples = 0;
  const planning::BatchPlanner no_search(no_search_options);

  // Starts: the block below the desk top; goals: the region of Table I.
  planning::GoalSamplerOptions so = iiwa_goal_options(21);
  so.region = Eigen::AlignedBox3d(Eigen::Vector3d(0.3, -0.6, 0.15), Eigen::Vector3d(0.9, 0.6, 0.5));
  planning::GoalSampler starts(desk.problem, so);
  planning::GoalSampler goals(desk.problem, iiwa_goal_options(22));
  json result;
  for (const auto& [key, sampler, random_start] :
       {std::tuple<const char*, planning::GoalSampler*, bool>{"random_starts", &starts, true},
        std::tuple<const char*, planning::GoalSampler*, bool>{"random_goals", &goals, false}}) {
    const Drawn d = draw(desk.problem, *sampler, random_start, count);
    Tally with, without;
    json cases = json::array();
    std::vector<double> horizons;
    for (std::size_t i = 0; i < d.problems.size(); ++i) {
      const Problem& p = d.problems[i];
      horizons.push_back(p.horizon);
      const Run r = plan_once(planner, p);
      const Run b = plan_once(no_search, p);
      json c = {{"case", i},
                {"horizon_s", p.horizon},
                {"start_q", as_vector(p.start_q)},
                {"goal_q", as_vector(p.goal.q)},
                {"planner", plan_case(p, r, with)},
                {"without_path_search", plan_case(p, b, without)}};
      std::cerr << key << " " << i << ": " << c["planner"].dump() << "\n";
      cases.push_back(c);
    }
    result[key] = {{"problems", d.problems.size()},
                   {"refused_by_check_problem", d.refused},
                   {"refusals", d.refusals},
                   {"candidates_drawn", sampler->attempts()},
                   {"horizon_s_median", median(horizons)},
                   {"horizon_s_max", max_of(horizons)},
                   {"planner", with.summary(d.problems.size())},
                   {"without_path_search", without.summary(d.problems.size())},
                   {"cases", cases}};
  }
  result["settings"] = {{"count", count},
                        {"walk_samples_per_interval", kWalkSamples},
                        {"start_seed", 21},
                        {"goal_seed", 22},
                        {"time", "wall time of BatchPlanner::plan (build, solve, validate)"}};
  std::cout << result.dump(2) << "\n\n";
  if (!json_path.empty()) std::ofstream(json_path) << result.dump(2) << "\n";

  std::cout << "| problems | planner | success | clear successes | min self / floor clearance "
               "(mm) | median time (ms) | max time (ms) | failures |\n"
               "|---|---|---|---|---|---|---|---|\n";
  for (const char* key : {"random_starts", "random_goals"}) {
    for (const char* mode : {"planner", "without_path_search"}) {
      const json& s = result[key][mode];
      std::string kinds;
      for (const auto& [k, n] : s["failure_kinds"].items()) {
        kinds += (kinds.empty() ? "" : "; ") + k + "(" + std::to_string(n.get<int>()) + ")";
      }
      std::cout << "| " << key << " | " << mode << " | " << s["successes"] << "/" << s["runs"]
                << " | " << s["successes_clear"] << " | "
                << cell(json_number(s["min_self_clearance_m"]), 1e3, 1) << " / "
                << cell(json_number(s["min_floor_clearance_m"]), 1e3, 1) << " | "
                << cell(json_number(s["time_s_median"]), 1e3) << " | "
                << cell(json_number(s["time_s_max"]), 1e3) << " | " << (kinds.empty() ? "–" : kinds)
                << " |\n";
    }
  }
  return 0;
}

}  // namespace
}  // namespace kinograph::bench

int main(int argc, char** argv) { return kinograph::bench::run(argc, argv); }

// N iiwa arms around a shared table (bench/multi_robot/README.md): 20 seeded random
// crossing-goal problems per N, each planned by the centralized planner (all arms in one factor
// graph) and by a fleet of daemons (one kinographd process per arm over LCM, fleet_run.h);
// success, time and summed objective per problem and planner, as JSON, a Markdown table and a
// plot.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bench/common/bench_flags.h"
#include "bench/common/bench_stats.h"
#include "bench/common/cpu_clock.h"
#include "bench/multi_robot/cell_generator.h"
#include "bench/multi_robot/fleet_run.h"
#include "kinograph/cell/cell.h"
#include "kinograph/cell/composite_problem.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/validate.h"
#include "render/image.h"
#include "render/plot.h"

namespace kinograph::bench {
namespace {

namespace fs = std::filesystem;

struct Args {
  std::string robots = "2,4,8";
  int problems = 20;
  int seed = 1;
  std::string cells_dir;  // where the generated cells are written (empty: a fresh temp dir)
  std::string out = "multi_robot.json";
  std::string table;  // Markdown table file (empty: stdout only)
  std::string plot;   // PNG
  bool generate_only = false;
  std::string write_cell;   // write one cell (--robots N, --seed) here and stop
  std::string urdf;         // the URDF as written in it (default: the source tree's, absolute)
  std::string report;       // results files (comma-separated) to tabulate and plot, no runs
  bool centralized = true;  // plan each cell centrally
  bool distributed = true;  // and with one daemon per arm
  FleetRunOptions fleet;
};

std::vector<int> robot_counts(const std::string& list) {
  std::vector<int> out;
  std::stringstream ss(list);
  for (std::string item; std::getline(ss, item, ',');) out.push_back(std::stoi(item));
  return out;
}

// One problem planned centrally: success (the composite and every robot's own plan
// validate), CPU and wall time, the summed objective and the solver's counts.
nlohmann::json plan_centralized(const std::string& path) {
  const cell::Cell c = cell::load_cell(path);
  const cell::CompositeProblem cp = cell::composite_problem(c);
  const planning::BatchPlanner planner;
  const double cpu0 = cpu_seconds();
  const auto wall0 = std::chrono::steady_clock::now();
  const planning::Plan plan = planner.plan(cp.problem);
  const double cpu = cpu_seconds() - cpu0;
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  bool valid = plan.success();
  for (std::size_t i = 0; valid && i < c.robots.size(); ++i) {
    valid =
        planning::validate(c.robots[i].scene.problem, cell::robot_plan(plan, cp.ranges[i])).valid;
  }
  // Each arm's own objective in its own scene, summed: the distributed side's measure. It is
  // the composite's soft cost, since every soft term (the GP prior) is per joint.
  double objective = 0;
  for (std::size_t i = 0; i < c.robots.size(); ++i) {
    objective += plan_objective(c.robots[i].scene.problem, cell::robot_plan(plan, cp.ranges[i]));
  }
  nlohmann::json j;
  j["success"] = valid;
  j["cpu_s"] = cpu;
  j["wall_s"] = wall;
  j["objective"] = objective;
  j["iterations"] = plan.stats.iterations;
  j["attempts"] = plan.stats.attempts;
  j["status"] = planning::to_string(plan.stats.status);
  j["min_clearance"] = plan.validation.min_clearance;
  if (!valid) {
    j["reason"] =
        plan.validation.failures.empty() ? plan.stats.reason : plan.validation.failures.front();
  }
  return j;
}

// The figure `key` of one side ("centralized", "distributed") of every problem that ran it,
// of the successful ones only when `successes`.
std::vector<double> figures(const nlohmann::json& group, const std::string& side,
                            const std::string& key, bool successes) {
  std::vector<double> out;
  for (const auto& p : group["problems"]) {
    const auto& s = p[side];
    if (s.is_null() || (successes && !s["success"].get<bool>())) continue;
    if (s.contains(key) && s[key].is_number()) out.push_back(s[key].get<double>());
  }
  return out;
}

// "k/n" of the problems that ran `side`, "–" when none did.
std::string successes(const nlohmann::json& group, const std::string& side) {
  int ok = 0, n = 0;
  for (const auto& p : group["problems"]) {
    if (p[side].is_null()) continue;
    ++n;
    ok += p[side]["success"].get<bool>() ? 1 : 0;
  }
  return n == 0 ? "–" : fmt::format("{}/{}", ok, n);
}

std::string median_max(const std::vector<double>& v, int precision) {
  return cell(median(v), 1, precision) + " / " + cell(max_of(v), 1, precision);
}

// Per problem both sides solved: the distributed summed objective over the centralized one.
std::vector<double> objective_ratios(const nlohmann::json& group) {
  std::vector<double> out;
  for (const auto& p : group["problems"]) {
    const auto &c = p["centralized"], &d = p["distributed"];
    if (c.is_null() || d.is_null() || !c["success"].get<bool>() || !d["success"].get<bool>()) {
      continue;
    }
    out.push_back(d["objective"].get<double>() / c["objective"].get<double>());
  }
  return out;
}

std::string markdown(const nlohmann::json& results) {
  // Times, objectives and messages of successes; replans and daemons' CPU of every problem run.
  std::string t =
      "| N arms | problems | centralized success | CPU median / max [s] | objective median | "
      "distributed success | mutually clear median / max [s] | settled median / max [s] | "
      "daemons' CPU median [s] | replans median / max | messages median / max | objective "
      "median | objective distributed / centralized median |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& group : results["groups"]) {
    t += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                     group["robots"].get<int>(), group["problems"].size(),
                     successes(group, "centralized"),
                     median_max(figures(group, "centralized", "cpu_s", false), 2),
                     cell(median(figures(group, "centralized", "objective", true)), 1, 1),
                     successes(group, "distributed"),
                     median_max(figures(group, "distributed", "time_to_mutually_clear_s", true), 2),
                     median_max(figures(group, "distributed", "time_to_settled_s", true), 2),
                     cell(median(figures(group, "distributed", "daemons_cpu_s", false)), 1, 2),
                     median_max(figures(group, "distributed", "replans", false), 0),
                     median_max(figures(group, "distributed", "messages", true), 0),
                     cell(median(figures(group, "distributed", "objective", true)), 1, 1),
                     cell(median(objective_ratios(group)), 1, 2));
  }
  return t;
}

// One panel: per arm count, the successes' log10 times (the times of 2 and 8 arms differ by two
// orders of magnitude) sorted, as steps: the k-th fastest spans [k − 1, k], so a curve ends at
// the number of successes.
render::Image time_panel(const nlohmann::json& results, const std::string& side,
                         const std::string& key, const std::string& title) {
  std::vector<render::PlotSeries> series;
  for (const auto& group : results["groups"]) {
    std::vector<double> v = figures(group, side, key, true);
    std::sort(v.begin(), v.end());
    render::PlotSeries s;
    s.label = fmt::format("N = {} arms", group["robots"].get<int>());
    for (std::size_t k = 0; k < v.size(); ++k) {
      for (double x : {double(k), k + 1.0}) {
        s.t.push_back(x);
        s.values.push_back(Eigen::VectorXd::Constant(1, std::log10(v[k])));
      }
    }
    if (!s.t.empty()) series.push_back(std::move(s));
  }
  render::TorquePlotOptions o;
  o.title = title;
  o.y_label = "log10 time [s]";
  o.x_label = "problems solved";
  o.joint_names = {""};
  o.height = 380;
  return render::plot_torques(series, o);
}

// The centralized planner's CPU time over the fleet's wall time until its plans were first
// clear of each other, one panel each.
void write_plot(const nlohmann::json& results, const std::string& path) {
  const render::Image top =
      time_panel(results, "centralized", "cpu_s", "Centralized planner: CPU time, sorted");
  const render::Image bottom =
      time_panel(results, "distributed", "time_to_mutually_clear_s",
                 "Daemons: wall time to clear, sorted");
  render::Image both(top.width, top.height + bottom.height);
  std::copy(top.rgba.begin(), top.rgba.end(), both.rgba.begin());
  std::copy(bottom.rgba.begin(), bottom.rgba.end(), both.rgba.begin() + top.rgba.size());
  render::write_png(both, path);
}

// The table (stdout and --table) and the plot (--plot) of a results file.
void report(const nlohmann::json& results, const Args& args) {
  const std::string table = markdown(results);
  std::cout << table;
  if (!args.table.empty()) std::ofstream(args.table) << table;
  if (!args.plot.empty()) write_plot(results, args.plot);
}

int write_one_cell(const Args& args) {
  CellGeneratorOptions g;
  g.robots = std::stoi(args.robots);
  g.seed = static_cast<std::uint64_t>(args.seed);
  g.urdf = args.urdf.empty() ? std::string(KINOGRAPH_SOURCE_DIR) + "/robots/iiwa14/iiwa14.urdf"
                             : args.urdf;
  g.path = args.write_cell;
  std::ofstream(args.write_cell) << generate_cell(g, fs::path(args.write_cell).stem().string());
  return 0;
}

// Merges `from` into `into` (groups of the same arm count and seed): a problem of the same cell
// name fills the sides `into` has not run (a centralized-only and a distributed-only run of the
// same cells make one row per problem); any other problem is appended.
void merge_group(nlohmann::json& into, const nlohmann::json& from) {
  for (const auto& p : from["problems"]) {
    const std::string name = fs::path(p["cell"].get<std::string>()).stem().string();
    nlohmann::json* same = nullptr;
    for (auto& q : into["problems"]) {
      if (fs::path(q["cell"].get<std::string>()).stem().string() == name) same = &q;
    }
    if (same == nullptr) {
      into["problems"].push_back(p);
      continue;
    }
    for (const char* side : {"centralized", "distributed"}) {
      if ((*same)[side].is_null() && !p[side].is_null()) (*same)[side] = p[side];
    }
  }
}

// --report A.json,B.json: the groups of several results files in one table and plot.
int report_files(const Args& args) {
  nlohmann::json merged;
  merged["groups"] = nlohmann::json::array();
  std::stringstream ss(args.report);
  for (std::string file; std::getline(ss, file, ',');) {
    std::ifstream in(file);
    if (!in) throw std::runtime_error("cannot read '" + file + "'");
    const nlohmann::json j = nlohmann::json::parse(in);
    for (nlohmann::json group : j["groups"]) {
      group["seed"] = j["seed"];
      nlohmann::json* same = nullptr;
      for (auto& g : merged["groups"]) {
        if (g["robots"] == group["robots"] && g["seed"] == group["seed"]) same = &g;
      }
      if (same != nullptr) {
        merge_group(*same, group);
      } else {
        merged["groups"].push_back(group);
      }
    }
  }
  std::sort(merged["groups"].begin(), merged["groups"].end(),
            [](const nlohmann::json& a, const nlohmann::json& b) {
              return a["robots"].get<int>() < b["robots"].get<int>();
            });
  report(merged, args);
  return 0;
}

int run(const Args& args) {
  if (!args.write_cell.empty()) return write_one_cell(args);
  if (!args.report.empty()) return report_files(args);
  const bool plan = !args.generate_only;
  // Refused before any cell is planned, rather than after an hour of centralized plans.
  if (plan && args.distributed) require_multicast(args.fleet.lcm_url);
  std::string dir = args.cells_dir;
  if (dir.empty()) {
    char tmpl[] = "/tmp/multi_robot_cells.XXXXXX";
    if (!mkdtemp(tmpl)) throw std::runtime_error("cannot make a temporary folder");
    dir = tmpl;
  }
  fs::create_directories(dir);
  CellGeneratorOptions g;
  g.urdf = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/iiwa14/iiwa14.urdf";
  nlohmann::json results;
  results["seed"] = args.seed;
  results["cells_dir"] = dir;
  results["fleet"] = {{"timeout_s", args.fleet.timeout_s},
                      {"quiet_s", args.fleet.quiet_s},
                      {"status_period_s", args.fleet.status_period_s},
                      {"lcm_url", args.fleet.lcm_url}};
  for (int n : robot_counts(args.robots)) {
    results["groups"].push_back({{"robots", n}, {"problems", nlohmann::json::array()}});
    for (int k = 0; k < args.problems; ++k) {
      g.robots = n;
      g.seed = static_cast<std::uint64_t>(args.seed) * 100 + k;
      const std::string name = fmt::format("iiwa{}_p{:02d}", n, k);
      const std::string path = (fs::path(dir) / (name + ".yaml")).string();
      g.path = path;
      std::ofstream(path) << generate_cell(g, name);
      nlohmann::json problem;
      problem["cell"] = path;
      problem["centralized"] = nullptr;
      problem["distributed"] = nullptr;
      if (plan && args.centralized) {
        problem["centralized"] = plan_centralized(path);
        const auto& c = problem["centralized"];
        std::cerr << fmt::format(
            "{} centralized: {} cpu {:.2f} s objective {:.1f}{}\n", name,
            c["success"].get<bool>() ? "ok" : "FAILED", json_number(c["cpu_s"]),
            json_number(c["objective"]),
            c.contains("reason") ? " (" + c["reason"].get<std::string>() + ")" : "");
      }
      if (plan && args.distributed) {
        problem["distributed"] = run_fleet(path, args.fleet);
        const auto& d = problem["distributed"];
        std::cerr << fmt::format(
            "{} distributed: {} clear after {:.2f} s, settled after {:.2f} s, {} replans, {} "
            "messages, objective {:.1f}{}\n",
            name, d["success"].get<bool>() ? "ok" : "FAILED",
            json_number(d["time_to_mutually_clear_s"]), json_number(d["time_to_settled_s"]),
            d["replans"].get<int>(), d["messages"].get<int>(), json_number(d["objective"]),
            d.contains("reason") ? " (" + d["reason"].get<std::string>() + ")" : "");
      }
      results["groups"].back()["problems"].push_back(problem);
      // Written after every problem, so a run cut short keeps what it measured.
      std::ofstream(args.out) << results.dump(1) << "\n";
    }
  }
  if (plan) report(results, args);
  return 0;
}

}  // namespace
}  // namespace kinograph::bench

int main(int argc, char** argv) {
  using namespace kinograph::bench;
  Args args;
  Flags flags("multi_robot_bench");
  flags.value("--robots", "LIST", [&](const std::string& s) { args.robots = s; })
      .value("--problems", &args.problems)
      .value("--seed", &args.seed)
      .value("--cells-dir", &args.cells_dir)
      .value("--out", &args.out)
      .value("--table", &args.table)
      .value("--plot", &args.plot)
      .value("--write-cell", &args.write_cell)
      .value("--urdf", &args.urdf)
      .value("--report", &args.report)
      .toggle("--generate-only", [&] { args.generate_only = true; })
      .toggle("--centralized-only", [&] { args.distributed = false; })
      .toggle("--distributed-only", [&] { args.centralized = false; })
      .value("--distributed-timeout", &args.fleet.timeout_s)
      .value("--quiet", &args.fleet.quiet_s)
      .value("--lcm-url", &args.fleet.lcm_url)
      .value("--kinographd", &args.fleet.kinographd);
  args.fleet.kinographd = KINOGRAPHD_PATH;
  if (!flags.parse(argc, argv)) return 64;
  if (!args.centralized && !args.distributed) {
    std::cerr
        << "multi_robot_bench: --centralized-only and --distributed-only exclude each other\n";
    return 64;
  }
  spdlog::set_level(spdlog::level::warn);
  try {
    return run(args);
  } catch (const std::exception& e) {
    std::cerr << "multi_robot_bench: " << e.what() << "\n";
    return 1;
  }
}

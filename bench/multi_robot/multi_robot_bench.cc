// N iiwa arms around a shared table (bench/multi_robot/README.md): 20 seeded random
// crossing-goal problems per N, planned by the centralized planner (all arms in one factor
// graph); success, CPU time and summed objective per problem, as JSON, a Markdown table and a
// plot. The distributed side (one daemon per arm over LCM) fills the "distributed" slot of each
// problem when run (not by this program).
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
  std::string write_cell;  // write one cell (--robots N, --seed) here and stop
  std::string urdf;        // the URDF as written in it (default: the source tree's, absolute)
  std::string report;      // results files (comma-separated) to tabulate and plot, no runs
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
  nlohmann::json j;
  j["success"] = valid;
  j["cpu_s"] = cpu;
  j["wall_s"] = wall;
  j["objective"] = plan.stats.cost;  // ½Σ‖r‖² of the soft terms: the robots' own summed
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

std::string markdown(const nlohmann::json& results) {
  std::string t =
      "| N arms | problems | centralized success | CPU time median [s] | CPU time max [s] | "
      "summed objective median | distributed success | time to mutually clear median / max "
      "[s] | replans | messages |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& group : results["groups"]) {
    std::vector<double> cpu, objective;
    int ok = 0;
    for (const auto& p : group["problems"]) {
      const auto& c = p["centralized"];
      if (c["success"].get<bool>()) {
        ++ok;
        objective.push_back(json_number(c["objective"]));
      }
      cpu.push_back(json_number(c["cpu_s"]));
    }
    const int n = static_cast<int>(group["problems"].size());
    t += fmt::format("| {} | {} | {}/{} | {} | {} | {} | – | – | – | – |\n",
                     group["robots"].get<int>(), n, ok, n, cell(median(cpu), 1, 2),
                     cell(max_of(cpu), 1, 2), cell(median(objective), 1, 1));
  }
  return t;
}

// One curve per arm count: log10 of each problem's CPU time against the problem's index (the
// times of 2 and 8 arms differ by two orders of magnitude).
void write_plot(const nlohmann::json& results, const std::string& path) {
  std::vector<render::PlotSeries> series;
  for (const auto& group : results["groups"]) {
    render::PlotSeries s;
    s.label = fmt::format("N = {} arms", group["robots"].get<int>());
    for (const auto& p : group["problems"]) {
      s.t.push_back(static_cast<double>(s.t.size()));
      s.values.push_back(
          Eigen::VectorXd::Constant(1, std::log10(json_number(p["centralized"]["cpu_s"]))));
    }
    if (!s.t.empty()) series.push_back(std::move(s));
  }
  render::TorquePlotOptions o;
  o.title = "Centralized planner";
  o.y_label = "log10 CPU time [s]";
  o.x_label = "problem";
  o.joint_names = {"CPU time per problem"};
  o.height = 420;
  render::write_png(render::plot_torques(series, o), path);
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

// --report A.json,B.json: the groups of several results files in one table and plot.
int report_files(const Args& args) {
  nlohmann::json merged;
  merged["groups"] = nlohmann::json::array();
  std::stringstream ss(args.report);
  for (std::string file; std::getline(ss, file, ',');) {
    std::ifstream in(file);
    if (!in) throw std::runtime_error("cannot read '" + file + "'");
    const nlohmann::json j = nlohmann::json::parse(in);
    for (const auto& group : j["groups"]) merged["groups"].push_back(group);
  }
  report(merged, args);
  return 0;
}

int run(const Args& args) {
  if (!args.write_cell.empty()) return write_one_cell(args);
  if (!args.report.empty()) return report_files(args);
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
  results["distributed"] =
      "slot: per problem, 'distributed' = {success, time_to_mutually_clear_s, replans, messages}"
      " from one kinographd per arm over LCM (bench/multi_robot/README.md)";
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
      if (!args.generate_only) {
        problem["centralized"] = plan_centralized(path);
        problem["distributed"] = nullptr;
        const auto& c = problem["centralized"];
        std::cerr << fmt::format(
            "{}: {} cpu {:.2f} s objective {:.1f}{}\n", name,
            c["success"].get<bool>() ? "ok" : "FAILED", json_number(c["cpu_s"]),
            json_number(c["objective"]),
            c.contains("reason") ? " (" + c["reason"].get<std::string>() + ")" : "");
      }
      results["groups"].back()["problems"].push_back(problem);
      // Written after every problem, so a run cut short keeps what it measured.
      std::ofstream(args.out) << results.dump(1) << "\n";
    }
  }
  if (!args.generate_only) report(results, args);
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
      .toggle("--generate-only", [&] { args.generate_only = true; });
  if (!flags.parse(argc, argv)) return 64;
  spdlog::set_level(spdlog::level::warn);
  try {
    return run(args);
  } catch (const std::exception& e) {
    std::cerr << "multi_robot_bench: " << e.what() << "\n";
    return 1;
  }
}

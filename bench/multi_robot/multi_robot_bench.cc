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

void write_plot(const nlohmann::json& results, const std::string& path) {
  render::PlotSeries series;
  series.label = "centralized (filled: success)";
  render::TorquePlotOptions o;
  o.title = "Centralized planner: CPU time per problem";
  o.y_label = "CPU time [s]";
  o.x_label = "problem";
  const auto& groups = results["groups"];
  const std::size_t problems = groups[0]["problems"].size();
  for (std::size_t k = 0; k < problems; ++k) {
    series.t.push_back(static_cast<double>(k));
    Eigen::VectorXd v(groups.size());
    for (std::size_t g = 0; g < groups.size(); ++g) {
      v[g] = k < groups[g]["problems"].size()
                 ? json_number(groups[g]["problems"][k]["centralized"]["cpu_s"])
                 : std::nan("");
    }
    series.values.push_back(v);
  }
  for (const auto& g : groups)
    o.joint_names.push_back(fmt::format("N = {} arms", g["robots"].get<int>()));
  o.columns = static_cast<int>(groups.size());
  render::write_png(render::plot_torques({series}, o), path);
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

int run(const Args& args) {
  if (!args.write_cell.empty()) return write_one_cell(args);
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
    nlohmann::json group;
    group["robots"] = n;
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
      group["problems"].push_back(problem);
    }
    results["groups"].push_back(group);
  }
  std::ofstream(args.out) << results.dump(1) << "\n";
  if (args.generate_only) return 0;
  const std::string table = markdown(results);
  std::cout << table;
  if (!args.table.empty()) std::ofstream(args.table) << table;
  if (!args.plot.empty()) write_plot(results, args.plot);
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

// `kinograph check-together SCENE_A PLAN_A SCENE_B PLAN_B ...`: several robots' plans on a common
// clock checked against each other (every robot's bodies against every other's at and between
// the knots, kinograph/fleet/joint_clearance.h); prints the closest approach and exits 0 when
// they stay clear, 2 when they do not, 1 on bad input.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "kinograph/fleet/joint_clearance.h"
#include "kinograph/planning/io/plan_json.h"
#include "kinograph/planning/io/scene.h"
#include "tools/command_registry.h"
#include "tools/number_list.h"

namespace kinograph::tools {
namespace {

struct CheckTogetherArgs {
  std::vector<std::string> files;  // scene, plan, scene, plan, ...
  std::string start;               // s on the common clock, one per robot, comma-separated
  double clearance = 0.0;
  int samples = 10;
};

// The plan file's "start_utime" (µs of the robot's clock, written by send-goal), if any.
// @throws CommandFailure when the file is not JSON or the key is not an integer.
std::optional<std::int64_t> plan_start_utime(const std::string& path) {
  std::ifstream in(path);
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    throw CommandFailure("plan '" + path + "' is not JSON: " + e.what());
  }
  if (!json.contains("start_utime")) return std::nullopt;
  if (!json["start_utime"].is_number_integer()) {
    throw CommandFailure("plan '" + path + "': start_utime must be an integer (µs)");
  }
  return json["start_utime"].get<std::int64_t>();
}

void run_check_together(const CheckTogetherArgs& args) {
  if (args.files.size() < 4 || args.files.size() % 2 != 0) {
    throw CommandFailure("check-together needs pairs SCENE PLAN for at least two robots, got " +
                             std::to_string(args.files.size()) + " files",
                         kExitUsage);
  }
  const size_t n = args.files.size() / 2;
  const std::vector<double> start =
      args.start.empty() ? std::vector<double>{} : parse_number_list(args.start, "--start", n);
  std::vector<fleet::RobotPlan> robots;
  std::vector<std::optional<std::int64_t>> utimes;
  for (size_t i = 0; i < n; ++i) {
    const std::string& scene_path = args.files[2 * i];
    const std::string& plan_path = args.files[2 * i + 1];
    fleet::RobotPlan robot;
    try {
      const planning::Scene scene = planning::load_scene(scene_path);
      robot.model = scene.problem.model;
      robot.plan = planning::read_plan(plan_path, *robot.model);
    } catch (const std::exception& e) {
      throw CommandFailure(e.what());
    }
    robot.name = std::filesystem::path(scene_path).stem().string();
    for (const fleet::RobotPlan& other : robots) {
      if (other.name == robot.name) robot.name += "#" + std::to_string(i + 1);
    }
    utimes.push_back(start.empty() ? plan_start_utime(plan_path) : std::nullopt);
    robot.offset = start.empty() ? 0.0 : start[i];
    robots.push_back(std::move(robot));
  }
  // Plans that say when they start (on the robots' common clock) are placed there, relative
  // to the earliest; without --start, plans that do not say start together at 0.
  std::optional<std::int64_t> origin;
  for (const auto& u : utimes) {
    if (u && (!origin || *u < *origin)) origin = u;
  }
  for (size_t i = 0; i < n; ++i) {
    if (utimes[i]) robots[i].offset = static_cast<double>(*utimes[i] - *origin) * 1e-6;
  }
  fleet::JointClearance c;
  try {
    c = fleet::joint_clearance(robots, {.samples_per_interval = args.samples});
  } catch (const std::invalid_argument& e) {
    throw CommandFailure(e.what());
  }
  std::cout << "check-together: " << n << " robots, " << c.samples << " common times\n";
  for (size_t i = 0; i < n; ++i) {
    const planning::Plan& p = robots[i].plan;
    std::cout << "  " << robots[i].name << ": " << args.files[2 * i + 1] << " from t = "
              << robots[i].offset + p.t.front() << " s to " << robots[i].offset + p.t.back()
              << " s\n";
  }
  std::cout << "closest approach: " << fleet::describe(c) << "\n";
  if (!c.clear(args.clearance)) {
    std::ostringstream why;
    why << "the robots do not keep " << args.clearance << " m apart: " << fleet::describe(c);
    throw CommandFailure(why.str(), kExitInvalidPlan);
  }
  std::cout << "clear (required clearance " << args.clearance << " m)\n";
}

const bool kCheckTogetherRegistered = register_command([](CLI::App& root) {
  auto args = std::make_shared<CheckTogetherArgs>();
  CLI::App* cmd = root.add_subcommand(
      "check-together",
      "Check several robots' plans against each other on a common clock (SCENE PLAN pairs, "
      "robots placed at their scenes' robot.base): exit 0 when clear, 2 when not");
  cmd->add_option("files", args->files, "SCENE PLAN pairs, one per robot (at least two)")
      ->required();
  cmd->add_option("--start", args->start,
                  "Common-clock time (s) of each plan's t = 0, one per robot; default: the plan "
                  "files' start_utime relative to the earliest, else 0");
  cmd->add_option("--clearance", args->clearance,
                  "Required distance (m) between robots (default 0: no contact)");
  cmd->add_option("--samples", args->samples,
                  "Points per plan interval, knot included (default 10)")
      ->check(CLI::PositiveNumber);
  cmd->callback([args] { run_check_together(*args); });
});

}  // namespace
}  // namespace kinograph::tools

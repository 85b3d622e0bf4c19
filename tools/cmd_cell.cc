// Cells of several robots (robots/cells/): `kinograph plan-cell CELL.yaml --out DIR` plans all
// robots in one factor graph (the centralized planner) and writes one plan file per robot
// (DIR/<robot>.json, with its scene DIR/<robot>.yaml) and the composite plan (DIR/cell.json);
// `kinograph render-cell CELL.yaml DIR --out strip.png` draws the robots' plans in one picture,
// each robot in its own colour.
// Exit status: 0 every plan validates, 2 one does not, 1 bad input.
#include <spdlog/spdlog.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "kinograph/cell/cell.h"
#include "kinograph/cell/composite_problem.h"
#include "kinograph/planning/io/data_dir.h"
#include "kinograph/planning/io/plan_json.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/validate.h"
#include "render/cell_scene.h"
#include "render/failure_mark.h"
#include "render/image.h"
#include "render/plan_scene.h"
#include "render/scene_camera.h"
#include "render/scene_renderer.h"
#include "tools/command_registry.h"
#include "tools/formulation.h"
#include "tools/picture_options.h"
#include "tools/plan_file.h"

namespace kinograph::tools {
namespace {

namespace fs = std::filesystem;

cell::Cell read_cell(const std::string& path) {
  try {
    return cell::load_cell(path);
  } catch (const std::exception& e) {
    throw CommandFailure(e.what());
  }
}

std::string robot_plan_path(const std::string& dir, const std::string& robot) {
  return (fs::path(dir) / (robot + ".json")).string();
}

struct PlanCellArgs {
  std::string cell;
  std::string out = "cell_plans";
  std::string formulation;
  bool quiet = false;
};

// The composite plan file: the plan of the composite robot, the cell and its robots' files in
// place of a URDF.
void write_composite(const planning::Plan& plan, const cell::Cell& c,
                     const cell::CompositeProblem& composite, planning::Formulation formulation,
                     const std::string& dir) {
  planning::Scene scene;
  scene.source = c.source;
  scene.problem = composite.problem;
  scene.obstacle_names = composite.obstacle_names;
  nlohmann::json json = planning::plan_to_json(plan, scene);
  json["stats"]["formulation"] = planning::to_string(formulation);
  json["robot"] = {{"cell", planning::data_relative_path(fs::absolute(c.source).string())},
                   {"robots", nlohmann::json::array()}};
  for (const cell::CellRobot& robot : c.robots) {
    json["robot"]["robots"].push_back({{"name", robot.name}, {"plan", robot.name + ".json"}});
  }
  write_plan_json(std::move(json), scene, (fs::path(dir) / "cell.json").string());
}

void run_plan_cell(const PlanCellArgs& args) {
  cell::Cell c = read_cell(args.cell);
  planning::BatchPlannerOptions options;
  options.formulation = choose_formulation(c.robots.front().scene, args.formulation);
  const planning::BatchPlanner planner(options);
  cell::CompositeProblem composite;
  try {
    cell::resolve_pose_goals(c, planner);
    composite = cell::composite_problem(c);
  } catch (const std::exception& e) {
    throw CommandFailure("cell '" + args.cell + "': " + e.what());
  }
  const planning::Plan plan = planner.plan(composite.problem);
  std::error_code ec;
  fs::create_directories(args.out, ec);
  if (ec) throw CommandFailure("cannot create the folder '" + args.out + "': " + ec.message());
  write_composite(plan, c, composite, options.formulation, args.out);
  bool all_valid = plan.success();
  std::ostringstream report;
  for (std::size_t i = 0; i < c.robots.size(); ++i) {
    const cell::CellRobot& robot = c.robots[i];
    planning::Plan own;
    if (plan.q.rows() > 0) {
      own = cell::robot_plan(plan, composite.ranges[i]);
      own.validation = planning::validate(robot.scene.problem, own, options.validation);
    } else {
      own = plan;  // a plan that failed before any solve has no columns to split
    }
    all_valid = all_valid && own.success();
    const std::string scene_path = (fs::path(args.out) / (robot.name + ".yaml")).string();
    std::ofstream scene_file(scene_path);
    scene_file << planning::scene_to_yaml(robot.scene);
    if (!scene_file) throw CommandFailure("cannot write the scene file '" + scene_path + "'");
    write_plan_file(own, robot.scene, options.formulation, robot_plan_path(args.out, robot.name));
    report << "robot " << robot.name << ": " << (own.success() ? "valid" : "INVALID")
           << ", min clearance " << own.validation.min_clearance << " m"
           << (own.validation.failures.empty() ? "" : ": " + own.validation.failures.front())
           << "\n";
  }
  if (!args.quiet) {
    std::cout << "plan-cell " << c.name << " (" << args.cell << ", " << c.robots.size()
              << " robots, " << composite.problem.model->nq() << " joints) -> " << args.out << "\n"
              << "formulation: " << planning::to_string(options.formulation) << "\n"
              << "composite: " << planning::summarize(plan) << report.str();
  }
  if (!all_valid) {
    throw CommandFailure("the centralized plan of '" + args.cell + "' does not validate (" +
                             planning::to_string(plan.stats.status) + ")",
                         kExitInvalidPlan);
  }
}

struct RenderCellArgs : PictureArgs {
  std::string cell;
  std::string plans;
};

void run_render_cell(const RenderCellArgs& args) {
  const cell::Cell c = read_cell(args.cell);
  try {
    std::vector<dynamics::ComposedPart> parts;
    std::vector<render::Trajectory> trajectories;
    std::vector<std::string> ee_frames;
    std::optional<std::string> failure;
    for (const cell::CellRobot& robot : c.robots) {
      const dynamics::Model& model = *robot.scene.problem.model;
      parts.push_back({robot.name, &model, Eigen::Isometry3d::Identity()});
      const planning::Plan plan =
          planning::read_plan(robot_plan_path(args.plans, robot.name), model);
      if (!failure) {
        if (const auto why = render::failure_text(plan)) failure = robot.name + ": " + *why;
      }
      trajectories.push_back(render::plan_trajectory(model, plan));
      ee_frames.push_back(model.frames.back().name);
    }
    std::vector<dynamics::ComposedRange> ranges;
    const dynamics::Model model = render::colour_robots(dynamics::compose(parts, &ranges), ranges);
    render::RenderScene scene;
    scene.model = &model;
    scene.trajectory = render::cell_trajectory(trajectories, ranges);
    const cell::CellRobot& first = c.robots.front();
    for (std::size_t i = 0; i < first.scene.problem.obstacles.size(); ++i) {
      render::SceneObstacle o;
      o.obstacle = first.scene.problem.obstacles[i];
      o.name = first.scene.obstacle_names[i];
      scene.obstacles.push_back(o);
    }
    scene.camera = render::read_scene_camera(c.source);
    scene.paths = render::robot_paths(ranges, ee_frames);
    const render::FrameOptions options = frame_options(args, args.frames);
    render::SceneRenderer renderer = make_renderer(args);
    render::RenderResult result =
        args.style == "ghost" ? renderer.ghost(scene, options) : renderer.strip(scene, options);
    if (failure) render::mark_failed(result.image, *failure);
    render::write_png(result.image, args.out);
    spdlog::info("render-cell: wrote {} ({}x{}, {} robots, {})", args.out, args.width, args.height,
                 c.robots.size(), args.style);
  } catch (const CommandFailure&) {
    throw;
  } catch (const std::exception& e) {
    throw CommandFailure(e.what());
  }
}

const bool kRegisteredPlan = register_command([](CLI::App& root) {
  auto args = std::make_shared<PlanCellArgs>();
  CLI::App* cmd = root.add_subcommand(
      "plan-cell",
      "Plan all robots of a cell (YAML) in one factor graph (centralized) and write one plan "
      "file per robot, its scene, and the composite plan");
  cmd->add_option("cell", args->cell, "Cell file (YAML), e.g. robots/cells/two_iiwa_table.yaml")
      ->required();
  cmd->add_option("--out,-o", args->out,
                  "Folder to write <robot>.json, <robot>.yaml and cell.json into")
      ->capture_default_str();
  add_formulation_option(cmd, args->formulation);
  cmd->add_flag("--quiet,-q", args->quiet, "Print nothing; only the exit status tells");
  cmd->callback([args] { run_plan_cell(*args); });
});

const bool kRegisteredRender = register_command([](CLI::App& root) {
  auto args = std::make_shared<RenderCellArgs>();
  CLI::App* cmd = root.add_subcommand(
      "render-cell",
      "Draw the plans of a cell's robots (PLANS/<robot>.json) in one frame strip or ghost view, "
      "each robot in its own colour");
  cmd->add_option("cell", args->cell, "Cell file (YAML)")->required();
  cmd->add_option("plans", args->plans, "Folder holding one plan file <robot>.json per robot")
      ->required();
  add_picture_options(cmd, *args);
  cmd->callback([args] { run_render_cell(*args); });
});

}  // namespace
}  // namespace kinograph::tools

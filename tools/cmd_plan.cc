// `kinograph plan SCENE.yaml --out plan.json [--init L|W --warm plan.json]
// [--formulation condensed|dfg]`: plans a scene with the batch planner, prints a summary
// (formulation, success, every validation figure, iterations, solve time, cost) and writes the
// plan file.
// Exit status: 0 the plan validates, 2 it does not, 1 bad input (files, flags).
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/io/plan_json.h"
#include "kinograph/planning/io/scene.h"
#include "tools/command_registry.h"
#include "tools/formulation.h"

namespace kinograph::tools {
namespace {

struct PlanArgs {
  std::string scene;
  std::string out = "plan.json";
  std::string init;  // empty: the scene's choice
  std::string warm;
  std::string formulation;
  bool quiet = false;
};

void run_plan(const PlanArgs& args) {
  planning::Scene scene;
  try {
    scene = planning::load_scene(args.scene);
  } catch (const std::exception& e) {
    throw CommandFailure(e.what());
  }
  std::string init = args.init.empty() ? scene.planner.init : args.init;
  std::string warm = args.warm.empty() ? scene.planner.warm : args.warm;
  if (!args.warm.empty() && args.init.empty()) init = "W";
  planning::BatchPlannerOptions options;
  options.formulation = choose_formulation(scene, args.formulation);
  std::optional<planning::Plan> warm_plan;
  if (init == "W") {
    if (warm.empty()) throw CommandFailure("--init W needs --warm PLAN.json");
    try {
      warm_plan = planning::read_plan(warm, *scene.problem.model);
    } catch (const std::exception& e) {
      throw CommandFailure(e.what());
    }
  }
  const planning::BatchPlanner planner(options);
  const planning::Plan plan = planner.plan(scene.problem, warm_plan ? &*warm_plan : nullptr);
  const planning::Formulation used = planner.options().formulation;
  write_plan_file(plan, scene, used, args.out);
  if (!args.quiet) {
    std::cout << "plan " << scene.problem.name << " (" << args.scene << ") -> " << args.out << "\n"
              << "formulation: " << planning::to_string(used) << "\n"
              << planning::summarize(plan);
  }
  if (!plan.success()) {
    throw CommandFailure("the plan of '" + args.scene + "' does not validate (" +
                             planning::to_string(plan.stats.status) + ")",
                         kExitInvalidPlan);
  }
}

const bool kPlanRegistered = register_command([](CLI::App& root) {
  auto args = std::make_shared<PlanArgs>();
  CLI::App* cmd = root.add_subcommand(
      "plan", "Plan a scene (YAML) with the batch DFGP planner and write the plan (JSON)");
  cmd->add_option("scene", args->scene, "Scene file (YAML), e.g. robots/scenes/rr_reach.yaml")
      ->required();
  cmd->add_option("--out,-o", args->out, "Plan file to write (JSON)")->capture_default_str();
  cmd->add_option("--init", args->init,
                  "Initialization: L (straight line) or W (warm start from --warm); default: "
                  "the scene's planner.init")
      ->check(CLI::IsMember({"L", "W"}));
  cmd->add_option("--warm", args->warm, "Plan file (JSON) to warm-start from (implies --init W)");
  add_formulation_option(cmd, args->formulation);
  cmd->add_flag("--quiet,-q", args->quiet, "Print nothing; only the exit status tells");
  cmd->callback([args] { run_plan(*args); });
});

}  // namespace
}  // namespace kinograph::tools

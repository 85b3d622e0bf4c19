// `kinograph validate SCENE.yaml PLAN.json`: checks a plan file against its scene with the
// solver-independent validator, prints every figure, and exits 0 when the plan is valid,
// 2 when it is not, 1 on bad input. `--start-from-plan` takes the plan's first knot as the start
// (a replan that continues a motion under way, e.g. a fleet daemon's without states).
#include <iostream>
#include <memory>
#include <string>

#include "kinograph/planning/io/plan_json.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/validate.h"
#include "tools/command_registry.h"

namespace kinograph::tools {
namespace {

struct ValidateArgs {
  std::string scene;
  std::string plan;
  bool start_from_plan = false;
};

void run_validate(const ValidateArgs& args) {
  planning::Scene scene;
  planning::Plan plan;
  try {
    scene = planning::load_scene(args.scene);
    plan = planning::read_plan(args.plan, *scene.problem.model);
  } catch (const std::exception& e) {
    throw CommandFailure(e.what());
  }
  if (args.start_from_plan && plan.q.rows() > 0) {
    scene.problem.start_q = plan.q.row(0).transpose();
    scene.problem.start_qd = plan.qd.row(0).transpose();
  }
  const planning::Validation validation = planning::validate(scene.problem, plan);
  std::cout << "validate " << args.plan << " against " << args.scene << "\n"
            << planning::summarize(validation);
  if (!validation.valid) {
    throw CommandFailure("plan '" + args.plan + "' is not valid for '" + args.scene + "'",
                         kExitInvalidPlan);
  }
}

const bool kValidateRegistered = register_command([](CLI::App& root) {
  auto args = std::make_shared<ValidateArgs>();
  CLI::App* cmd = root.add_subcommand(
      "validate",
      "Check a plan (JSON) against its scene (YAML): dynamics, consistency, limits, "
      "collision, goal; exit non-zero when invalid");
  cmd->add_option("scene", args->scene, "Scene file (YAML)")->required();
  cmd->add_option("plan", args->plan, "Plan file (JSON)")->required();
  cmd->add_flag("--start-from-plan", args->start_from_plan,
                "Start where the plan's first knot is (q, qd), not at the scene's start: a replan "
                "that continues a motion under way");
  cmd->callback([args] { run_validate(*args); });
});

}  // namespace
}  // namespace kinograph::tools

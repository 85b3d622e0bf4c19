// `kinograph replan SCENE.yaml CHANGE.yaml [--out-before a.json] [--out-after b.json]
// [--formulation condensed|dfg]`: plans a scene, applies a change file (new goal, measured
// start, horizon, obstacles added, moved or removed; robots/scenes/changes/) and replans
// incrementally (iDFGP), printing both plans and what the replan did (ISAM2 updates, cliques
// re-eliminated, fallback). The formulation is that of the batch solves (the first plan and any
// fallback). Exit status: 0 the replan validates, 2 it (or the first plan) does not, 1 bad
// input (files, flags).
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "kinograph/planning/io/plan_json.h"
#include "kinograph/planning/io/replan_change.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/replanner.h"
#include "tools/command_registry.h"
#include "tools/formulation.h"

namespace kinograph::tools {
namespace {

struct ReplanArgs {
  std::string scene, change;
  std::string out_before, out_after;
  std::string formulation;  // empty: the scene's
  bool quiet = false;
};

std::string describe(const planning::ReplanReport& r, const planning::Plan& plan) {
  const planning::IncrementalStats& s = r.statistics;
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "replan: method %s%s, %d ISAM2 updates, %d multiplier rounds, %ld variables "
                "re-eliminated, %ld relinearized, %d factors replaced, %d added, "
                "%d re-added; incremental %.1f ms, total %.1f ms\n",
                r.method.c_str(),
                r.retried_from_scratch ? " (planned from scratch: the replan did not validate)"
                : r.fell_back ? " (fell back: the incremental plan did not validate)"
                              : "",
                s.updates,
                s.rounds, s.variables_reeliminated, s.variables_relinearized, s.factors_replaced,
                s.factors_added, s.factors_readded, s.incremental_time_s * 1e3,
                plan.stats.solve_time_s * 1e3);
  return buf;
}

void run_replan(const ReplanArgs& args) {
  planning::Scene scene;
  planning::SceneChange change;
  try {
    scene = planning::load_scene(args.scene);
    change = planning::load_change(args.change, scene);
  } catch (const std::exception& e) {
    throw CommandFailure(e.what());
  }
  // The formulation of every batch solve: the first plan and any fallback.
  planning::ReplannerOptions options;
  options.incremental.batch.formulation = choose_formulation(scene, args.formulation);
  planning::Replanner planner(options);
  const planning::Formulation used = planner.options().incremental.batch.formulation;
  const planning::Plan before = planner.plan(scene.problem, /*new_goal=*/true);
  if (!args.quiet) {
    std::cout << "plan " << scene.problem.name << " (" << args.scene << ")\n"
              << "formulation: " << planning::to_string(used) << "\n"
              << planning::summarize(before);
  }
  try {
    if (!args.out_before.empty()) write_plan_file(before, scene, used, args.out_before);
  } catch (const std::exception& e) {
    throw CommandFailure(e.what());
  }
  if (!before.success()) {
    throw CommandFailure("the plan of '" + args.scene + "' does not validate (" +
                             planning::to_string(before.stats.status) + "); nothing to replan",
                         2);
  }
  planner.prepare();  // as the daemon does while it waits for a change
  const planning::Plan after = planner.replan(change.change);
  if (!args.quiet) {
    std::cout << "\nreplan after " << args.change << "\n"
              << describe(planner.last_report(), after) << planning::summarize(after);
  }
  try {
    if (!args.out_after.empty()) {
      write_plan_file(after, planning::apply_change(scene, change), used, args.out_after);
    }
  } catch (const std::exception& e) {
    throw CommandFailure(e.what());
  }
  if (!after.success()) {
    throw CommandFailure("the replan after '" + args.change + "' does not validate (" +
                             planning::to_string(after.stats.status) + ")",
                         kExitInvalidPlan);
  }
}

const bool kReplanRegistered = register_command([](CLI::App& root) {
  auto args = std::make_shared<ReplanArgs>();
  CLI::App* cmd = root.add_subcommand(
      "replan",
      "Plan a scene, apply a change file (goal, start, horizon, obstacles) and replan "
      "incrementally (iDFGP)");
  cmd->add_option("scene", args->scene, "Scene file (YAML), e.g. robots/scenes/rr_reach.yaml")
      ->required();
  cmd->add_option("change", args->change,
                  "Change file (YAML), e.g. robots/scenes/changes/rr_reach_goal.yaml")
      ->required();
  cmd->add_option("--out-before", args->out_before, "Plan file (JSON) of the first plan");
  cmd->add_option("--out-after", args->out_after, "Plan file (JSON) of the replan");
  add_formulation_option(cmd, args->formulation);
  cmd->add_flag("--quiet,-q", args->quiet, "Print nothing; only the exit status tells");
  cmd->callback([args] { run_replan(*args); });
});

}  // namespace
}  // namespace kinograph::tools

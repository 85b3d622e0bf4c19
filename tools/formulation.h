#pragma once
// The batch formulation of the CLI's planning verbs (plan, replan): chosen by --formulation or
// the scene's planner.formulation, printed, and recorded in the plan files they write.
#include <CLI/CLI.hpp>
#include <string>

#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/plan.h"

namespace kinograph::tools {

/// Adds `--formulation condensed|dfg` to a planning verb; an empty `name` means the scene's.
void add_formulation_option(CLI::App* cmd, std::string& name);

/// The formulation to plan `scene` in: `name` when given, else the scene's planner.formulation.
/// @throws CommandFailure for a name that is neither "condensed" nor "dfg".
planning::Formulation choose_formulation(const planning::Scene& scene, const std::string& name);

/// Writes the plan file of `plan` (planning::write_plan) with the formulation its planner was
/// given as stats.formulation, which SolveStats does not hold.
/// @throws CommandFailure when the file cannot be written.
void write_plan_file(const planning::Plan& plan, const planning::Scene& scene,
                     planning::Formulation formulation, const std::string& path);

}  // namespace kinograph::tools

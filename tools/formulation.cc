#include "tools/formulation.h"

#include "kinograph/planning/io/plan_json.h"
#include "tools/command_registry.h"
#include "tools/plan_file.h"

namespace kinograph::tools {

void add_formulation_option(CLI::App* cmd, std::string& name) {
  cmd->add_option("--formulation", name,
                  "condensed (tau = RNEA per step) or dfg (the paper's full dynamic factor "
                  "graph); default: the scene's planner.formulation")
      ->check(CLI::IsMember({"condensed", "dfg"}));
}

planning::Formulation choose_formulation(const planning::Scene& scene, const std::string& name) {
  const std::string chosen = name.empty() ? scene.planner.formulation : name;
  const auto formulation = planning::formulation_from_name(chosen);
  if (!formulation) {
    throw CommandFailure("formulation '" + chosen + "' is neither 'condensed' nor 'dfg'");
  }
  return *formulation;
}

void write_plan_file(const planning::Plan& plan, const planning::Scene& scene,
                     planning::Formulation formulation, const std::string& path) {
  nlohmann::json json = planning::plan_to_json(plan, scene);
  json["stats"]["formulation"] = planning::to_string(formulation);
  write_plan_json(std::move(json), scene, path);
}

}  // namespace kinograph::tools

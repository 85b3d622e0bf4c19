#include "tools/plan_file.h"

#include <filesystem>
#include <fstream>
#include <iostream>

#include "kinograph/planning/io/data_dir.h"
#include "kinograph/planning/io/plan_json.h"
#include "tools/command_registry.h"

namespace kinograph::tools {

void write_plan_json(nlohmann::json json, const planning::Scene& scene, const std::string& path) {
  if (!scene.source.empty()) json["scene"] = planning::data_relative_path(scene.source);
  const std::filesystem::path p(path);
  if (p.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(p.parent_path(), ec);
  }
  std::ofstream out(path);
  out << json.dump(1) << "\n";
  if (!out) throw CommandFailure("cannot write plan file '" + path + "'");
}

void write_plan_json(const planning::Plan& plan, const planning::Scene& scene,
                     const std::string& path) {
  write_plan_json(planning::plan_to_json(plan, scene), scene, path);
}

std::optional<std::string> plan_scene_path(const std::string& plan_path) {
  std::ifstream in(plan_path);
  if (!in) throw CommandFailure("cannot read plan file '" + plan_path + "'");
  const nlohmann::json json = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (!json.is_object() || !json.contains("scene")) return std::nullopt;
  if (!json["scene"].is_string()) {
    throw CommandFailure("plan '" + plan_path + "': 'scene' must be a string");
  }
  const std::string scene = json["scene"].get<std::string>();
  const std::optional<std::string> path = planning::resolve_plan_path(scene, plan_path);
  if (!path) {
    // Only the camera comes from the scene: say so and frame automatically.
    std::cerr << "kinograph: note: plan '" << plan_path << "' names scene '" << scene
              << "', which is not found (looked in the working directory, next to the plan and "
                 "in "
              << planning::describe_data_dirs() << "); framing automatically (--scene gives one)\n";
  }
  return path;
}

}  // namespace kinograph::tools

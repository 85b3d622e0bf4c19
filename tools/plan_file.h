#pragma once
// Plan files as the CLI writes them: the library's plan JSON plus the scene it was planned
// for (key "scene", relative to the data directory when shipped), so that `render` uses the
// scene's camera without being told the scene again.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/plan.h"

namespace kinograph::tools {

/// Writes `json` (a plan_to_json) to `path` with scene.source recorded under "scene",
/// creating the folder. @throws CommandFailure when the file cannot be written.
void write_plan_json(nlohmann::json json, const planning::Scene& scene, const std::string& path);

/// write_plan_json of planning::plan_to_json(plan, scene).
void write_plan_json(const planning::Plan& plan, const planning::Scene& scene,
                     const std::string& path);

/// The scene file a plan file names under "scene", resolved as the plan's other paths
/// (planning::resolve_plan_path); nullopt when it names none, or (said on stderr) one that is
/// nowhere. @throws CommandFailure when the plan cannot be read or "scene" is not a string.
std::optional<std::string> plan_scene_path(const std::string& plan_path);

}  // namespace kinograph::tools

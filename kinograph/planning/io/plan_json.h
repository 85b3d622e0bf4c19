#pragma once
// Plan files (JSON): a plan with the robot and obstacles it was planned for, read by the
// renderer, by `kinograph validate` and for warm starts. Format: docs/plan_file.md.
#include <Eigen/Core>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "kinograph/dynamics/model.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/io/scene.h"

namespace kinograph::planning {

/// A plan file that cannot be read: what() names the file and the offending key.
class PlanFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The plan file format this kinograph writes ("format_version"); it reads this one, older ones
/// and files without the field (written before it existed).
inline constexpr int kPlanFormatVersion = 2;

/// The solver statistics as a JSON object (every field of SolveStats).
nlohmann::json to_json(const SolveStats& stats);
/// The validation as a JSON object (every figure of Validation, failures as a list).
nlohmann::json to_json(const Validation& validation);
/// Reads back to_json(SolveStats); absent keys keep their defaults. Throws PlanFileError.
SolveStats stats_from_json(const nlohmann::json& json, const std::string& source = "");
/// Reads back to_json(Validation); absent keys keep their defaults. Throws PlanFileError.
Validation validation_from_json(const nlohmann::json& json, const std::string& source = "");

/// A human-readable report of a plan: success, the solver statistics (status, iterations,
/// solve time, cost) and every validation figure, one per line, then the failures.
std::string summarize(const Plan& plan);
/// The validation part of summarize().
std::string summarize(const Validation& validation);

/// The plan file of `plan`, solved for `scene` (robot, payload and obstacles come from it).
nlohmann::json plan_to_json(const Plan& plan, const Scene& scene);
/// Writes plan_to_json to `path`; throws PlanFileError if it cannot be written.
void write_plan(const Plan& plan, const Scene& scene, const std::string& path);

/// The "format_version" of a plan file, 0 when absent (written before the field existed).
/// @throws PlanFileError naming `source` when it is not an integer >= 1 or is newer than
/// kPlanFormatVersion.
int plan_format_version(const nlohmann::json& json, const std::string& source = "");

/// Parses a plan file for `model`: columns are matched to the model's joints by
/// "joint_names" (by position when absent) and the sizes checked. Throws PlanFileError.
Plan plan_from_json(const nlohmann::json& json, const dynamics::Model& model,
                    const std::string& source = "");
/// The JSON of a plan file, for a caller that reads it more than one way (plan_from_json,
/// plan_file_from_json) without parsing it twice. Throws PlanFileError naming the file.
nlohmann::json read_plan_json(const std::string& path);
/// Reads a plan file for `model` (see plan_from_json). Throws PlanFileError.
Plan read_plan(const std::string& path, const dynamics::Model& model);

/// Joint limits as a plan file lists them, one entry per "joint_names" column. A list the file
/// leaves out is empty; null entries (JSON's infinity) read as -inf for "lower", +inf else.
struct PlanLimits {
  std::vector<double> lower, upper, velocity, acceleration, effort;
};

/// What a plan file says besides its trajectory and solve: the robot it was planned for, the
/// obstacles and the joints' order and limits. Reading it needs no robot model.
struct PlanFileInfo {
  std::string source;  ///< file it was read from: names it in errors, anchors relative paths
  std::string name;    ///< "name"; empty when absent
  std::string urdf;    ///< "robot.urdf" as written (see resolve_plan_path)
  Eigen::Isometry3d base = Eigen::Isometry3d::Identity();  ///< "robot.base" (identity if absent)
  std::optional<PayloadSpec> payload;          ///< "robot.payload"
  std::vector<collision::Obstacle> obstacles;  ///< obstacles[i].id == i; "motion" as trajectory
  std::vector<std::string> obstacle_names;     ///< their "id"s ("obstacles[i]" when absent)
  std::vector<std::optional<Eigen::Vector4d>> obstacle_rgba;  ///< their "rgba", when given
  std::vector<std::string> joint_names;  ///< column order of q, qd, qdd, tau; empty if absent
  std::vector<std::string> unactuated;   ///< "unactuated": the passive joints, by name
  PlanLimits limits;
};

/// A plan file read whole: what it says, the robot it names and the plan in that robot's
/// joint order.
struct PlanFile {
  PlanFileInfo info;
  /// The URDF with the payload attached and the file's limits applied (load_plan_model).
  std::shared_ptr<const dynamics::Model> model;
  Plan plan;
};

/// Parses the robot, obstacles, joint names and limits of a plan file; mesh obstacles' files
/// are resolved (resolve_plan_path). Throws PlanFileError naming `source` and the key.
PlanFileInfo plan_info_from_json(const nlohmann::json& json, const std::string& source = "");
/// Finds a file a plan names: absolute as is; else relative to the working directory, the plan
/// file's directory or a data directory (data_dir.h), the first that exists. Empty when none does.
std::optional<std::string> resolve_plan_path(const std::string& path,
                                             const std::string& plan_source);
/// The robot a plan file names: its URDF, the payload attached and the file's limits applied
/// to the joints it names (so it is the problem's model). Throws PlanFileError.
dynamics::Model load_plan_model(const PlanFileInfo& info);
/// Parses a whole plan file (info, robot, plan). Throws PlanFileError.
PlanFile plan_file_from_json(const nlohmann::json& json, const std::string& source = "");
/// Reads a whole plan file, which needs nothing else to be used. Throws PlanFileError.
PlanFile read_plan_file(const std::string& path);

}  // namespace kinograph::planning

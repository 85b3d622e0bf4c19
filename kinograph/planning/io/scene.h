#pragma once
// Scene files (YAML): one planning problem with the robot it is posed for — URDF, payload,
// limit overrides, horizon, start, goal, obstacles, task constraints, objective weights and
// planner choices. The schema is documented in robots/scenes/README.md.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "kinograph/planning/problem.h"

namespace kinograph::planning {

/// A scene file that cannot be used: unreadable, not YAML, an unknown key, a wrong type or a
/// value out of range. what() names the file, the key path (e.g. "obstacles[1].size") and the
/// line when yaml-cpp knows it.
class SceneError : public std::runtime_error {
 public:
  SceneError(std::string file, std::string key, int line, const std::string& message);
  const std::string& file() const { return file_; }
  /// Dotted key path of the offending entry; empty for file-level errors.
  const std::string& key() const { return key_; }
  /// 1-based line of the offending entry, 0 when unknown.
  int line() const { return line_; }

 private:
  std::string file_, key_;
  int line_ = 0;
};

/// A solid box carried by the robot (scene key robot.payload), fixed in `frame` with its centre
/// at `offset`; attached with dynamics::attach_box_payload.
struct PayloadSpec {
  std::string frame;
  double mass = 0.0;                                 ///< kg
  Eigen::Vector3d size = Eigen::Vector3d::Zero();    ///< full extents (m)
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  ///< box centre in `frame` (m)
};

/// Replacement limits for one joint (scene key `limits.<joint>`); unset entries keep the URDF's.
/// An effort must be > 0 (a passive joint is listed in Scene::unactuated instead).
struct LimitOverride {
  std::optional<double> lower, upper, velocity, effort, acceleration;
};

enum class Formulation;  // kinograph/planning/batch/batch_planner.h

/// Planner choices stored with a scene; the CLI's and kinographd's flags override them.
struct PlannerSpec {
  std::string formulation = "condensed";  ///< "condensed" (τ = RNEA per step) or "dfg"
  std::string init = "L";                 ///< "L" straight line, "W" warm start from `warm`
  std::string warm;                       ///< plan file (JSON) for init W; resolved path
};

/// A parsed scene: the Problem plus what is needed to write it back (robot source, payload,
/// overrides, obstacle names) and the planner choices.
struct Scene {
  std::string source;     ///< file it was read from; empty when parsed from text
  std::string urdf;       ///< robot.urdf as written in the file
  std::string urdf_path;  ///< robot.urdf resolved to an absolute path
  /// robot.base: where the robot's root link stands in the world (identity by default);
  /// problem.model is placed there.
  Eigen::Isometry3d base = Eigen::Isometry3d::Identity();
  std::optional<PayloadSpec> payload;
  /// Limit overrides in file order, by joint name.
  std::vector<std::pair<std::string, LimitOverride>> limits;
  /// Passive joints (scene key `unactuated`), by name in file order: their torque is held at 0.
  std::vector<std::string> unactuated;
  /// Obstacle names; problem.obstacles[i] has id i and the name obstacle_names[i].
  std::vector<std::string> obstacle_names;
  std::string srdf;       ///< robot.srdf as written in the file; empty when none
  std::string srdf_path;  ///< robot.srdf resolved to an absolute path
  /// The scene's allowed_collisions link pairs, as named; problem.self_and_floor.allowed_pairs
  /// holds their bodies and the SRDF's.
  std::vector<std::pair<std::string, std::string>> allowed_collisions;
  PlannerSpec planner;
  /// The problem; problem.model is the URDF with payload attached and overrides applied.
  Problem problem;
};

/// Reads a scene file. Relative paths inside (URDF, meshes, warm-start plan) resolve against
/// the scene file's directory first, then the data directories (data_dir.h). Throws SceneError.
Scene load_scene(const std::string& path);

/// Parses scene text; `source` names it in errors and anchors relative paths (its directory;
/// the working directory when empty). Throws SceneError.
Scene parse_scene(const std::string& yaml, const std::string& source = "");

/// The YAML text of a scene (paths written resolved), such that parse_scene gives it back.
std::string scene_to_yaml(const Scene& scene);

/// The name of a shape kind in scene and plan files: box, sphere, cylinder, capsule or mesh.
std::string shape_kind_name(collision::ShapeKind kind);
/// The shape kind a scene or plan file names; nullopt for a name that is none of them.
std::optional<collision::ShapeKind> shape_kind_from_name(const std::string& name);

/// The batch formulation a planner.formulation names ("condensed" or "dfg"); nullopt for a name
/// that is neither.
std::optional<Formulation> formulation_from_name(const std::string& name);

/// Resolves a path named in a scene: absolute as is; else relative to `anchor_dir` if it
/// exists there, else relative to a data directory (data_dir.h). Empty when none holds it.
std::optional<std::string> resolve_scene_path(const std::string& path,
                                              const std::string& anchor_dir);

}  // namespace kinograph::planning

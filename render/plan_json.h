#pragma once
// The plan file (JSON) the planner writes and the renderer reads: robot, obstacles and the
// sampled trajectory with its torques. Field names are the contract with planning/.
//
// {"name": "...", "robot": {"urdf": "robots/iiwa14/iiwa14.urdf",
//            "payload": {"frame": "...", "mass": 2.0, "size": [x,y,z], "offset": [x,y,z]}},
//  "obstacles": [{"id": "desk", "shape": "box"|"sphere"|"cylinder"|"capsule"|"mesh",
//                 "size": [..], "mesh": "path", "position": [x,y,z], "quaternion": [w,x,y,z],
//                 "rgba": [r,g,b,a] (optional)}],
//  "joint_names": [...], "t": [...], "q": [[...],...], "qd": [[...]], "qdd": [[...]],
//  "tau": [[...]], "limits": {"effort": [...]}, "stats": {...}, "validation": {...}}
// Obstacles' "motion" (moving obstacles) is not read: they are drawn where "position" puts them.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "kinograph/dynamics/geometry.h"
#include "kinograph/dynamics/model.h"
#include "render/render_scene.h"

namespace kinograph::render {

/// A solid box carried by the robot, fixed in `frame` at `offset` (plan "robot.payload").
struct PlanPayload {
  std::string frame;
  double mass = 0.0;
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
};

/// One obstacle of a plan, as written in the file.
struct PlanObstacle {
  std::string id;
  std::string shape = "box";  ///< box, sphere, cylinder, capsule or mesh
  std::vector<double> size;   ///< box [x,y,z]; sphere [r]; cylinder/capsule [r, length]
  std::string mesh;           ///< mesh file (shape "mesh"), resolved like the URDF path
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond quaternion = Eigen::Quaterniond::Identity();
  std::optional<Eigen::Vector4d> rgba;
};

/// A plan file in memory. Vectors of joint values are indexed like `joint_names`.
struct PlanFile {
  std::string source;  ///< file it was read from (for messages and relative paths)
  std::string name;    ///< the plan's "name" (e.g. the problem's), empty when absent
  std::string urdf;    ///< as written: absolute, or relative to the repo root / plan file
  std::optional<PlanPayload> payload;
  std::vector<PlanObstacle> obstacles;
  std::vector<std::string> joint_names;
  std::vector<double> t;
  std::vector<Eigen::VectorXd> q, qd, qdd, tau;  ///< per time step; qd, qdd, tau may be empty
  std::vector<double> effort_limits;             ///< "limits.effort"; empty when absent
  nlohmann::json stats = nlohmann::json::object();
  nlohmann::json validation = nlohmann::json::object();
};

/// Reads a plan file; throws std::runtime_error naming the file and the offending key.
PlanFile read_plan_json(const std::string& path);
/// Parses a plan from JSON; `source` names it in error messages.
PlanFile parse_plan_json(const nlohmann::json& json, const std::string& source);
/// The JSON form of a plan (inverse of parse_plan_json).
nlohmann::json to_json(const PlanFile& plan);
/// Writes a plan file; throws std::runtime_error if the file cannot be written.
void write_plan_json(const PlanFile& plan, const std::string& path);

/// Finds a file a plan refers to: absolute; else relative to the working directory, the
/// plan file's directory, or the repository root, first that exists. Throws if none does.
std::string resolve_plan_path(const std::string& path, const std::string& plan_source);

/// The robot of a plan: its URDF (with the payload attached, if any). Throws naming the file.
dynamics::Model load_plan_model(const PlanFile& plan);
/// The plan's obstacles as world-posed shapes (body = -1), meshes resolved.
std::vector<dynamics::Geometry> plan_obstacles(const PlanFile& plan);
/// The plan's t and q, with columns reordered to the model's joint order when the plan names
/// its joints. Throws std::runtime_error if a model joint is missing from the plan.
Trajectory plan_trajectory(const PlanFile& plan, const dynamics::Model& model);

}  // namespace kinograph::render

#pragma once
// Plan files (JSON): a plan with the robot and obstacles it was planned for, read by the
// renderer (render/plan_json.h, same key names), by `kinograph validate` and for warm starts.
//
// {"name": "...", "robot": {"urdf": "robots/iiwa14/iiwa14.urdf",
//   "payload": {"frame": "...", "mass": 2.0, "size": [x,y,z], "offset": [x,y,z]}},
//  "obstacles": [{"id": "desk", "shape": "box", "size": [..], "mesh": "path",
//                 "position": [x,y,z], "quaternion": [w,x,y,z],
//                 "motion": [{"t": s, "position": [..], "quaternion": [..]}] (moving only)}],
//  "joint_names": [...], "t": [...], "q": [[...], ...], "qd": ..., "qdd": ..., "tau": ...,
//  "limits": {"lower": [...], "upper": [...], "velocity": [...], "acceleration": [...],
//             "effort": [...]}, "stats": {...}, "validation": {...}}
//
// JSON has no infinity: an infinite limit or clearance is written as null and read back as
// infinity; "limits.effort" is left out when any effort limit is infinite (the renderer reads
// it as plain numbers). NaN trajectory values are written as null and read back as NaN, so a
// broken plan still round-trips to the validator.
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "kinograph/dynamics/model.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/scene.h"

namespace kinograph::planning {

/// A plan file that cannot be read: what() names the file and the offending key.
class PlanFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

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

/// Parses a plan file for `model`: columns are matched to the model's joints by
/// "joint_names" (by position when absent) and the sizes checked. Throws PlanFileError.
Plan plan_from_json(const nlohmann::json& json, const dynamics::Model& model,
                    const std::string& source = "");
/// Reads a plan file for `model` (see plan_from_json). Throws PlanFileError.
Plan read_plan(const std::string& path, const dynamics::Model& model);

}  // namespace kinograph::planning

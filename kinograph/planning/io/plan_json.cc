#include "kinograph/planning/io/plan_json.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <system_error>

#include "kinograph/dynamics/base_placement.h"
#include "kinograph/dynamics/payload.h"
#include "kinograph/planning/io/data_dir.h"

namespace kinograph::planning {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr double kInf = std::numeric_limits<double>::infinity();

[[noreturn]] void fail(const std::string& source, const std::string& key,
                       const std::string& message) {
  std::string what = "plan '" + (source.empty() ? std::string("<json>") : source) + "'";
  if (!key.empty()) what += ": '" + key + "'";
  throw PlanFileError(what + ": " + message);
}

// Finite numbers as themselves; ±inf and NaN as null (JSON has neither).
json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json vector(const Eigen::VectorXd& v) {
  json out = json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(number(v[i]));
  return out;
}

json matrix_rows(const Eigen::MatrixXd& m) {
  json out = json::array();
  for (Eigen::Index k = 0; k < m.rows(); ++k) out.push_back(vector(m.row(k).transpose()));
  return out;
}

json pose_json(const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.linear());
  return {{"position", vector(pose.translation())}, {"quaternion", {q.w(), q.x(), q.y(), q.z()}}};
}

// A number, or null read as `null_value`.
double read_number(const json& j, const std::string& source, const std::string& key,
                   double null_value) {
  if (j.is_null()) return null_value;
  if (!j.is_number()) fail(source, key, "must be a number");
  return j.get<double>();
}

// A list of `size` finite numbers (any length when size < 0).
Eigen::VectorXd read_vector(const json& j, const std::string& source, const std::string& key,
                            int size) {
  if (!j.is_array()) fail(source, key, "must be an array of numbers");
  if (size >= 0 && j.size() != static_cast<std::size_t>(size)) {
    fail(source, key,
         "must have " + std::to_string(size) + " numbers, has " + std::to_string(j.size()));
  }
  Eigen::VectorXd v(j.size());
  for (std::size_t i = 0; i < j.size(); ++i) {
    const std::string item = key + "[" + std::to_string(i) + "]";
    if (!j[i].is_number()) fail(source, item, "must be a number");
    v[i] = j[i].get<double>();
    if (!std::isfinite(v[i])) fail(source, item, "must be finite");
  }
  return v;
}

// "position" and "quaternion" [w, x, y, z] of `j` (each optional: origin, identity).
Eigen::Isometry3d read_pose(const json& j, const std::string& source, const std::string& key) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  if (j.contains("position")) {
    pose.translation() = read_vector(j["position"], source, key + ".position", 3);
  }
  if (j.contains("quaternion")) {
    const Eigen::VectorXd q = read_vector(j["quaternion"], source, key + ".quaternion", 4);
    const Eigen::Quaterniond r(q[0], q[1], q[2], q[3]);
    if (r.norm() < 1e-9) fail(source, key + ".quaternion", "must not be zero");
    pose.linear() = r.normalized().toRotationMatrix();
  }
  return pose;
}

std::string directory_of(const std::string& source) {
  return source.empty() ? std::string() : fs::absolute(source).parent_path().string();
}

std::optional<PayloadSpec> read_payload(const json& robot, const std::string& source) {
  if (!robot.contains("payload") || robot["payload"].is_null()) return std::nullopt;
  const json& p = robot["payload"];
  if (!p.is_object()) fail(source, "robot.payload", "must be an object");
  PayloadSpec payload;
  if (!p.contains("frame") || !p["frame"].is_string()) {
    fail(source, "robot.payload.frame", "missing string");
  }
  payload.frame = p["frame"].get<std::string>();
  if (!p.contains("mass") || !p["mass"].is_number()) {
    fail(source, "robot.payload.mass", "missing number");
  }
  payload.mass = p["mass"].get<double>();
  if (!p.contains("size")) fail(source, "robot.payload.size", "missing array");
  payload.size = read_vector(p["size"], source, "robot.payload.size", 3);
  if (p.contains("offset")) {
    payload.offset = read_vector(p["offset"], source, "robot.payload.offset", 3);
  }
  return payload;
}

collision::Shape read_shape(const json& o, const std::string& source, const std::string& key) {
  std::string name = "box";  // hand-written files may leave the commonest shape out
  if (o.contains("shape")) {
    if (!o["shape"].is_string()) fail(source, key + ".shape", "must be a string");
    name = o["shape"].get<std::string>();
  }
  const std::optional<collision::ShapeKind> kind = shape_kind_from_name(name);
  if (!kind) {
    fail(source, key + ".shape",
         "is '" + name + "'; expected box, sphere, cylinder, capsule or mesh");
  }
  const std::string size_key = key + ".size";
  if (*kind == collision::ShapeKind::kMesh) {
    if (!o.contains("mesh") || !o["mesh"].is_string())
      fail(source, key + ".mesh", "missing string");
    const std::string mesh = o["mesh"].get<std::string>();
    const std::optional<std::string> path = resolve_plan_path(mesh, source);
    if (!path) fail(source, key + ".mesh", "file '" + mesh + "' not found");
    // The writer puts a mesh's scale under "size".
    Eigen::Vector3d scale = Eigen::Vector3d::Ones();
    if (o.contains("size")) scale = read_vector(o["size"], source, size_key, 3);
    return collision::Shape::mesh(*path, scale);
  }
  const int count = *kind == collision::ShapeKind::kBox      ? 3
                    : *kind == collision::ShapeKind::kSphere ? 1
                                                             : 2;
  if (!o.contains("size")) fail(source, size_key, "missing array");
  const Eigen::VectorXd size = read_vector(o["size"], source, size_key, count);
  if (size.minCoeff() <= 0) fail(source, size_key, "every size must be > 0");
  switch (*kind) {
    case collision::ShapeKind::kBox:
      return collision::Shape::box(size[0], size[1], size[2]);
    case collision::ShapeKind::kSphere:
      return collision::Shape::sphere(size[0]);
    case collision::ShapeKind::kCylinder:
      return collision::Shape::cylinder(size[0], size[1]);
    default:
      return collision::Shape::capsule(size[0], size[1]);
  }
}

collision::PoseTrajectory read_motion(const json& list, const std::string& source,
                                      const std::string& key) {
  if (!list.is_array() || list.empty()) {
    fail(source, key, "must be a non-empty array of {t, position, quaternion}");
  }
  std::vector<double> times;
  std::vector<Eigen::Isometry3d> poses;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const std::string sample = key + "[" + std::to_string(k) + "]";
    if (!list[k].is_object()) fail(source, sample, "must be an object");
    if (!list[k].contains("t") || !list[k]["t"].is_number()) {
      fail(source, sample + ".t", "missing number");
    }
    const double t = list[k]["t"].get<double>();
    if (!std::isfinite(t) || (!times.empty() && !(t > times.back()))) {
      fail(source, sample + ".t", "times must be finite and increase strictly");
    }
    times.push_back(t);
    poses.push_back(read_pose(list[k], source, sample));
  }
  return collision::PoseTrajectory(std::move(times), std::move(poses));
}

// "limits.<key>": one number per joint column (null as `null_value`); empty when absent.
std::vector<double> read_limit(const json& limits, const char* key, const std::string& source,
                               std::size_t columns, double null_value) {
  std::vector<double> out;
  if (!limits.contains(key)) return out;
  const std::string name = std::string("limits.") + key;
  const json& list = limits[key];
  if (!list.is_array()) fail(source, name, "must be an array of numbers");
  if (columns > 0 && list.size() != columns) {
    fail(source, name,
         "has " + std::to_string(list.size()) + " values for " + std::to_string(columns) +
             " joints");
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    out.push_back(read_number(list[i], source, name + "[" + std::to_string(i) + "]", null_value));
  }
  return out;
}

// Plan matrix `key` (rows × width) with columns picked by `column`.
Eigen::MatrixXd read_rows(const json& j, const char* key, const std::string& source,
                          std::size_t rows, const std::vector<int>& column, std::size_t width) {
  if (!j.contains(key)) fail(source, key, "missing array");
  const json& value = j.at(key);
  if (!value.is_array()) fail(source, key, "must be an array of arrays");
  if (value.size() != rows) {
    fail(source, key,
         "has " + std::to_string(value.size()) + " rows but 't' has " + std::to_string(rows));
  }
  Eigen::MatrixXd m(rows, column.size());
  for (std::size_t k = 0; k < rows; ++k) {
    const std::string row_key = std::string(key) + "[" + std::to_string(k) + "]";
    const json& row = value[k];
    if (!row.is_array() || row.size() != width) {
      fail(source, row_key, "must be an array of " + std::to_string(width) + " numbers");
    }
    for (std::size_t i = 0; i < column.size(); ++i) {
      m(k, i) = read_number(row[column[i]], source, row_key + "[" + std::to_string(column[i]) + "]",
                            std::numeric_limits<double>::quiet_NaN());
    }
  }
  return m;
}

// The figures of a validation by their plan-file keys, in file order.
std::array<std::pair<const char*, double*>, 15> validation_figures(Validation& v) {
  return {{{"max_dynamics_residual", &v.max_dynamics_residual},
           {"max_position_consistency", &v.max_position_consistency},
           {"max_velocity_consistency", &v.max_velocity_consistency},
           {"max_q_violation", &v.max_q_violation},
           {"max_qd_violation", &v.max_qd_violation},
           {"max_qdd_violation", &v.max_qdd_violation},
           {"max_tau_violation", &v.max_tau_violation},
           {"max_tau_violation_between", &v.max_tau_violation_between},
           {"max_unactuated_torque_between", &v.max_unactuated_torque_between},
           {"min_clearance", &v.min_clearance},
           {"goal_error", &v.goal_error},
           {"max_task_error", &v.max_task_error},
           {"max_unactuated_torque", &v.max_unactuated_torque},
           {"start_error", &v.start_error},
           {"final_velocity", &v.final_velocity}}};
}

// SolveTimes' parts by their names in plan files.
std::vector<std::pair<const char*, double*>> time_parts(SolveTimes& t) {
  return {{"initialization_s", &t.initialization_s},
          {"graph_building_s", &t.graph_building_s},
          {"linearization_s", &t.linearization_s},
          {"factorization_s", &t.factorization_s},
          {"triangular_solve_s", &t.triangular_solve_s},
          {"multipliers_s", &t.multipliers_s},
          {"between_knot_checks_s", &t.between_knot_checks_s},
          {"validation_s", &t.validation_s}};
}

}  // namespace

json to_json(const SolveStats& s) {
  SolveTimes times = s.times;
  json parts = json::object();
  for (const auto& [key, value] : time_parts(times)) parts[key] = number(*value);
  return {{"method", s.method},
          {"status", to_string(s.status)},
          {"reason", s.reason},
          {"iterations", s.iterations},
          {"outer_iterations", s.outer_iterations},
          {"linear_solves", s.linear_solves},
          {"attempts", s.attempts},
          {"solve_time_s", number(s.solve_time_s)},
          {"cost", number(s.cost)},
          {"max_constraint_violation", number(s.max_constraint_violation)},
          {"times", parts}};
}

json to_json(const Validation& v) {
  json j = {{"valid", v.valid}, {"failures", v.failures}};
  Validation copy = v;
  for (const auto& [key, value] : validation_figures(copy)) j[key] = number(*value);
  return j;
}

SolveStats stats_from_json(const json& j, const std::string& source) {
  SolveStats s;
  if (!j.is_object()) fail(source, "stats", "must be an object");
  const auto str = [&](const char* key, std::string& out) {
    if (!j.contains(key)) return;
    if (!j[key].is_string()) fail(source, std::string("stats.") + key, "must be a string");
    out = j[key].get<std::string>();
  };
  const auto integer = [&](const char* key, int& out) {
    if (!j.contains(key)) return;
    if (!j[key].is_number_integer())
      fail(source, std::string("stats.") + key, "must be an integer");
    out = j[key].get<int>();
  };
  const auto real = [&](const char* key, double& out) {
    if (j.contains(key)) out = read_number(j[key], source, std::string("stats.") + key, kInf);
  };
  str("method", s.method);
  if (j.contains("status")) {
    std::string name;
    str("status", name);
    try {
      s.status = plan_status_from_string(name);
    } catch (const std::invalid_argument& e) {
      fail(source, "stats.status", e.what());
    }
  }
  str("reason", s.reason);
  integer("iterations", s.iterations);
  integer("outer_iterations", s.outer_iterations);
  integer("linear_solves", s.linear_solves);
  integer("attempts", s.attempts);
  real("solve_time_s", s.solve_time_s);
  real("cost", s.cost);
  real("max_constraint_violation", s.max_constraint_violation);
  if (j.contains("times")) {
    const json& t = j["times"];
    if (!t.is_object()) fail(source, "stats.times", "must be an object");
    for (const auto& [key, value] : time_parts(s.times)) {
      if (t.contains(key))
        *value = read_number(t[key], source, std::string("stats.times.") + key, 0);
    }
  }
  return s;
}

Validation validation_from_json(const json& j, const std::string& source) {
  Validation v;
  if (!j.is_object()) fail(source, "validation", "must be an object");
  if (j.contains("valid")) {
    if (!j["valid"].is_boolean()) fail(source, "validation.valid", "must be true or false");
    v.valid = j["valid"].get<bool>();
  }
  if (j.contains("failures")) {
    if (!j["failures"].is_array()) fail(source, "validation.failures", "must be a list of strings");
    for (const json& f : j["failures"]) {
      if (!f.is_string()) fail(source, "validation.failures", "must be a list of strings");
      v.failures.push_back(f.get<std::string>());
    }
  }
  const auto figures = validation_figures(v);
  for (const auto& [key, out] : figures) {
    if (j.contains(key)) *out = read_number(j[key], source, std::string("validation.") + key, kInf);
  }
  return v;
}

std::string summarize(const Validation& v) {
  std::ostringstream os;
  os.precision(4);
  os << "validation: " << (v.valid ? "valid" : "INVALID") << "\n";
  const struct {
    const char* name;
    double value;
    const char* unit;
  } rows[] = {{"max dynamics residual |tau - ID|", v.max_dynamics_residual, "N·m"},
              {"max position consistency", v.max_position_consistency, "rad"},
              {"max velocity consistency", v.max_velocity_consistency, "rad/s"},
              {"max q limit violation", v.max_q_violation, "rad"},
              {"max qd limit violation", v.max_qd_violation, "rad/s"},
              {"max qdd limit violation", v.max_qdd_violation, "rad/s²"},
              {"max tau limit violation", v.max_tau_violation, "N·m"},
              {"max unactuated torque", v.max_unactuated_torque, "N·m"},
              {"max tau limit violation between knots", v.max_tau_violation_between, "N·m"},
              {"max unactuated torque between knots", v.max_unactuated_torque_between, "N·m"},
              {"min clearance", v.min_clearance, "m"},
              {"goal error", v.goal_error, ""},
              {"max task error", v.max_task_error, ""},
              {"start error", v.start_error, ""},
              {"final velocity", v.final_velocity, ""}};
  for (const auto& r : rows) {
    os << "  " << r.name << ": " << r.value << (r.unit[0] ? " " : "") << r.unit << "\n";
  }
  for (const std::string& f : v.failures) os << "  failed: " << f << "\n";
  return os.str();
}

std::string summarize(const Plan& plan) {
  std::ostringstream os;
  const SolveStats& s = plan.stats;
  os << "success: " << (plan.success() ? "yes" : "no") << "\n";
  os << "solver: " << s.method << ", status " << s.status;
  if (!s.reason.empty()) os << " (" << s.reason << ")";
  os << "\n  iterations: " << s.iterations << " LM, " << s.outer_iterations << " outer, "
     << s.linear_solves << " linear solves, " << s.attempts << " attempt(s)\n";
  os.precision(4);
  os << "  solve time: " << s.solve_time_s * 1e3 << " ms";
  if (s.times.total_s() > 0) {
    const SolveTimes& t = s.times;
    os << "\n  time by part (ms): initialization " << t.initialization_s * 1e3 << ", graphs "
       << t.graph_building_s * 1e3 << ", linearization " << t.linearization_s * 1e3
       << ", factorization " << t.factorization_s * 1e3 << ", triangular solves "
       << t.triangular_solve_s * 1e3 << ", multipliers " << t.multipliers_s * 1e3
       << ", checks between knots " << t.between_knot_checks_s * 1e3 << ", validation "
       << t.validation_s * 1e3 << ", the rest " << (s.solve_time_s - t.total_s()) * 1e3;
  }
  os << "\n";
  os << "  cost: " << s.cost << "\n";
  os << "  max constraint violation: " << s.max_constraint_violation << "\n";
  os << summarize(plan.validation);
  return os.str();
}

json plan_to_json(const Plan& plan, const Scene& scene) {
  const Problem& problem = scene.problem;
  json j;
  j["format_version"] = kPlanFormatVersion;
  j["name"] = problem.name;
  j["robot"]["urdf"] = data_relative_path(scene.urdf_path);
  if (!dynamics::is_identity_pose(scene.base)) j["robot"]["base"] = pose_json(scene.base);
  if (scene.payload) {
    const PayloadSpec& p = *scene.payload;
    j["robot"]["payload"] = {{"frame", p.frame},
                             {"mass", p.mass},
                             {"size", vector(p.size)},
                             {"offset", vector(p.offset)}};
  }
  j["obstacles"] = json::array();
  for (std::size_t i = 0; i < problem.obstacles.size(); ++i) {
    const collision::Obstacle& o = problem.obstacles[i];
    json oj;
    oj["id"] = i < scene.obstacle_names.size() ? scene.obstacle_names[i] : std::to_string(o.id);
    oj["shape"] = shape_kind_name(o.shape.kind);
    switch (o.shape.kind) {
      case collision::ShapeKind::kBox:
        oj["size"] = vector(o.shape.size);
        break;
      case collision::ShapeKind::kSphere:
        oj["size"] = {o.shape.size.x()};
        break;
      case collision::ShapeKind::kCylinder:
      case collision::ShapeKind::kCapsule:
        oj["size"] = {o.shape.size.x(), o.shape.size.y()};
        break;
      case collision::ShapeKind::kMesh:
        // The renderer reads a mesh's "size" as its scale.
        oj["size"] = vector(o.shape.mesh_scale);
        oj["mesh"] = o.shape.mesh_path;
        break;
    }
    const json pose = pose_json(o.pose);
    oj["position"] = pose["position"];
    oj["quaternion"] = pose["quaternion"];
    if (o.is_moving()) {
      oj["motion"] = json::array();
      for (std::size_t k = 0; k < o.trajectory.times().size(); ++k) {
        json sample = pose_json(o.trajectory.poses()[k]);
        sample["t"] = o.trajectory.times()[k];
        oj["motion"].push_back(sample);
      }
    }
    j["obstacles"].push_back(oj);
  }
  json names = json::array(), passive = json::array();
  json lower = json::array(), upper = json::array(), velocity = json::array(),
       acceleration = json::array(), effort = json::array();
  if (problem.model) {
    for (const dynamics::Body& b : problem.model->bodies) {
      names.push_back(b.joint_name);
      lower.push_back(number(b.limits.lower));
      upper.push_back(number(b.limits.upper));
      velocity.push_back(number(b.limits.velocity));
      acceleration.push_back(number(b.limits.acceleration));
      effort.push_back(number(b.limits.effort));
      if (!b.actuated) passive.push_back(b.joint_name);
    }
  }
  j["joint_names"] = names;
  j["unactuated"] = passive;
  j["t"] = plan.t;
  j["q"] = matrix_rows(plan.q);
  j["qd"] = matrix_rows(plan.qd);
  j["qdd"] = matrix_rows(plan.qdd);
  j["tau"] = matrix_rows(plan.tau);
  j["limits"] = {{"lower", lower},
                 {"upper", upper},
                 {"velocity", velocity},
                 {"acceleration", acceleration},
                 {"effort", effort}};
  j["stats"] = to_json(plan.stats);
  j["validation"] = to_json(plan.validation);
  return j;
}

void write_plan(const Plan& plan, const Scene& scene, const std::string& path) {
  const fs::path p(path);
  if (p.has_parent_path()) {
    std::error_code ec;
    fs::create_directories(p.parent_path(), ec);
  }
  std::ofstream out(path);
  if (!out) throw PlanFileError("cannot write plan file '" + path + "'");
  out << plan_to_json(plan, scene).dump(1) << "\n";
  if (!out) throw PlanFileError("error while writing plan file '" + path + "'");
}

int plan_format_version(const json& j, const std::string& source) {
  if (!j.is_object()) fail(source, "", "the top level must be a JSON object");
  if (!j.contains("format_version")) return 0;
  const json& v = j["format_version"];
  if (!v.is_number_integer() || v.get<long long>() < 1) {
    fail(source, "format_version", "must be an integer >= 1, is " + v.dump());
  }
  if (v.get<long long>() > kPlanFormatVersion) {
    fail(source, "format_version",
         "is " + v.dump() + ", newer than this kinograph reads (versions up to " +
             std::to_string(kPlanFormatVersion) + "); read it with a newer kinograph");
  }
  return v.get<int>();
}

Plan plan_from_json(const json& j, const dynamics::Model& model, const std::string& source) {
  plan_format_version(j, source);
  const int n = model.nq();
  std::vector<int> column(n);
  std::size_t width = n;
  if (j.contains("joint_names")) {
    const json& names = j["joint_names"];
    if (!names.is_array()) fail(source, "joint_names", "must be an array of strings");
    width = names.size();
    for (int i = 0; i < n; ++i) {
      column[i] = -1;
      for (std::size_t c = 0; c < names.size(); ++c) {
        if (!names[c].is_string()) fail(source, "joint_names", "must be an array of strings");
        if (names[c].get<std::string>() == model.bodies[i].joint_name)
          column[i] = static_cast<int>(c);
      }
      if (column[i] < 0) {
        fail(source, "joint_names",
             "has no joint '" + model.bodies[i].joint_name + "' of the robot");
      }
    }
  } else {
    for (int i = 0; i < n; ++i) column[i] = i;
  }
  Plan plan;
  if (!j.contains("t") || !j["t"].is_array()) fail(source, "t", "missing array of times");
  for (std::size_t k = 0; k < j["t"].size(); ++k) {
    const std::string key = "t[" + std::to_string(k) + "]";
    if (!j["t"][k].is_number()) fail(source, key, "must be a number");
    plan.t.push_back(j["t"][k].get<double>());
    if (k > 0 && !(plan.t[k] > plan.t[k - 1])) fail(source, key, "times must increase");
  }
  const std::size_t rows = plan.t.size();
  plan.q = read_rows(j, "q", source, rows, column, width);
  plan.qd = read_rows(j, "qd", source, rows, column, width);
  plan.qdd = read_rows(j, "qdd", source, rows, column, width);
  plan.tau = read_rows(j, "tau", source, rows, column, width);
  if (j.contains("stats")) plan.stats = stats_from_json(j["stats"], source);
  if (j.contains("validation")) plan.validation = validation_from_json(j["validation"], source);
  return plan;
}

json read_plan_json(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw PlanFileError("cannot open plan file '" + path + "'");
  // Parsed from the text: nlohmann reads a stream one character at a time through its buffer.
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  try {
    return json::parse(text);
  } catch (const json::exception& e) {  // parse_error, and out_of_range for a number like 1e309
    throw PlanFileError("plan '" + path + "' is not valid JSON: " + e.what());
  }
}

Plan read_plan(const std::string& path, const dynamics::Model& model) {
  return plan_from_json(read_plan_json(path), model, path);
}

PlanFileInfo plan_info_from_json(const json& j, const std::string& source) {
  plan_format_version(j, source);
  PlanFileInfo info;
  info.source = source;
  if (j.contains("name") && j["name"].is_string()) info.name = j["name"].get<std::string>();
  if (!j.contains("robot") || !j["robot"].is_object()) fail(source, "robot", "missing object");
  const json& robot = j["robot"];
  if (!robot.contains("urdf") || !robot["urdf"].is_string()) {
    fail(source, "robot.urdf", "missing string");
  }
  info.urdf = robot["urdf"].get<std::string>();
  if (robot.contains("base")) {
    if (!robot["base"].is_object()) fail(source, "robot.base", "must be an object");
    info.base = read_pose(robot["base"], source, "robot.base");
  }
  info.payload = read_payload(robot, source);
  if (j.contains("obstacles")) {
    const json& list = j["obstacles"];
    if (!list.is_array()) fail(source, "obstacles", "must be an array");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string key = "obstacles[" + std::to_string(i) + "]";
      const json& o = list[i];
      if (!o.is_object()) fail(source, key, "must be an object");
      collision::Obstacle obstacle;
      obstacle.id = static_cast<int>(i);
      obstacle.shape = read_shape(o, source, key);
      obstacle.pose = read_pose(o, source, key);
      if (o.contains("motion"))
        obstacle.trajectory = read_motion(o["motion"], source, key + ".motion");
      std::optional<Eigen::Vector4d> rgba;
      if (o.contains("rgba")) rgba = read_vector(o["rgba"], source, key + ".rgba", 4);
      info.obstacles.push_back(std::move(obstacle));
      info.obstacle_names.push_back(
          o.contains("id") && o["id"].is_string() ? o["id"].get<std::string>() : key);
      info.obstacle_rgba.push_back(rgba);
    }
  }
  // A list of joint names under `key` (absent: empty).
  const auto names_at = [&](const char* key, std::vector<std::string>& out) {
    if (!j.contains(key)) return;
    const json& names = j[key];
    if (!names.is_array()) fail(source, key, "must be an array of strings");
    for (const json& name : names) {
      if (!name.is_string()) fail(source, key, "must be an array of strings");
      out.push_back(name.get<std::string>());
    }
  };
  names_at("joint_names", info.joint_names);
  names_at("unactuated", info.unactuated);
  if (j.contains("limits")) {
    const json& limits = j["limits"];
    if (!limits.is_object()) fail(source, "limits", "must be an object");
    const std::size_t n = info.joint_names.size();
    info.limits.lower = read_limit(limits, "lower", source, n, -kInf);
    info.limits.upper = read_limit(limits, "upper", source, n, kInf);
    info.limits.velocity = read_limit(limits, "velocity", source, n, kInf);
    info.limits.acceleration = read_limit(limits, "acceleration", source, n, kInf);
    info.limits.effort = read_limit(limits, "effort", source, n, kInf);
  }
  return info;
}

std::optional<std::string> resolve_plan_path(const std::string& path,
                                             const std::string& plan_source) {
  // Error codes, as in resolve_scene_path: a name too long is not found, never a throw.
  std::error_code ec;
  const fs::path p(path);
  if (!p.is_absolute() && fs::exists(fs::current_path() / p, ec)) {
    const fs::path canonical = fs::weakly_canonical(fs::current_path() / p, ec);
    if (!ec) return canonical.string();
  }
  return resolve_scene_path(path, directory_of(plan_source));
}

dynamics::Model load_plan_model(const PlanFileInfo& info) {
  const std::optional<std::string> urdf = resolve_plan_path(info.urdf, info.source);
  if (!urdf) {
    fail(info.source, "robot.urdf",
         "file '" + info.urdf +
             "' not found (looked in the working directory, next to the plan and in " +
             describe_data_dirs() + ")");
  }
  dynamics::Model model;
  try {
    model = dynamics::Model::from_urdf_file(*urdf);
  } catch (const std::exception& e) {
    fail(info.source, "robot.urdf", std::string("cannot load the robot: ") + e.what());
  }
  try {
    if (!dynamics::is_identity_pose(info.base)) model = dynamics::place_base(model, info.base);
  } catch (const std::invalid_argument& e) {
    fail(info.source, "robot.base", e.what());
  }
  if (info.payload) {
    const PayloadSpec& p = *info.payload;
    Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
    offset.translation() = p.offset;
    try {
      model = dynamics::attach_box_payload(model, p.frame, p.mass, p.size, offset);
    } catch (const std::exception& e) {
      fail(info.source, "robot.payload", std::string("cannot attach: ") + e.what());
    }
  }
  // The file's limits are the problem's (scene overrides included), not only the URDF's.
  for (int i = 0; i < model.nq(); ++i) {
    dynamics::Body& body = model.bodies[i];
    std::size_t column = static_cast<std::size_t>(i);
    if (!info.joint_names.empty()) {
      const auto it = std::find(info.joint_names.begin(), info.joint_names.end(), body.joint_name);
      if (it == info.joint_names.end()) continue;  // plan_from_json names the missing joint
      column = static_cast<std::size_t>(it - info.joint_names.begin());
    }
    const auto apply = [&](const std::vector<double>& list, double& limit) {
      if (column < list.size()) limit = list[column];
    };
    apply(info.limits.lower, body.limits.lower);
    apply(info.limits.upper, body.limits.upper);
    apply(info.limits.velocity, body.limits.velocity);
    apply(info.limits.acceleration, body.limits.acceleration);
    if (column < info.limits.effort.size()) {
      body.limits.effort = info.limits.effort[column];
      if (!(body.limits.effort > 0)) {
        fail(info.source, "limits.effort",
             "joint '" + body.joint_name + "' has effort limit " +
                 std::to_string(body.limits.effort) +
                 "; a passive joint is named in \"unactuated\", not given effort 0");
      }
    }
  }
  for (const std::string& name : info.unactuated) {
    const auto it = std::find_if(model.bodies.begin(), model.bodies.end(),
                                 [&](const dynamics::Body& b) { return b.joint_name == name; });
    if (it == model.bodies.end()) {
      fail(info.source, "unactuated", "no joint '" + name + "' in the robot '" + model.name + "'");
    }
    it->actuated = false;
  }
  return model;
}

PlanFile plan_file_from_json(const json& j, const std::string& source) {
  PlanFile file;
  file.info = plan_info_from_json(j, source);
  auto model = std::make_shared<const dynamics::Model>(load_plan_model(file.info));
  file.plan = plan_from_json(j, *model, source);
  file.model = std::move(model);
  return file;
}

PlanFile read_plan_file(const std::string& path) {
  return plan_file_from_json(read_plan_json(path), path);
}

}  // namespace kinograph::planning

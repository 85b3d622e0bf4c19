#include "daemon/state_file.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "kinograph/collision/convex_shape.h"
#include "kinograph/collision/obstacle.h"
#include "kinograph/planning/io/scene.h"

namespace kinograph::daemon {

namespace {

using json = nlohmann::json;

constexpr char kFormat[] = "kinographd state";
constexpr int kVersion = 1;

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw StateFileError("state file '" + path + "': " + what);
}

json obstacle_to_json(const messages::ObstacleUpdate& o) {
  const Eigen::Vector3d p = o.pose.translation();
  const Eigen::Quaterniond r(o.pose.rotation());
  json j = {{"source", o.source},
            {"id", o.id},
            {"shape", planning::shape_kind_name(o.shape.kind)},
            {"size", {o.shape.size.x(), o.shape.size.y(), o.shape.size.z()}},
            {"position", {p.x(), p.y(), p.z()}},
            {"quaternion", {r.w(), r.x(), r.y(), r.z()}}};
  if (o.shape.kind == collision::ShapeKind::kMesh) {
    const Eigen::Vector3d& k = o.shape.mesh_scale;
    j["mesh"] = o.shape.mesh_path;  // resolved when it arrived
    j["scale"] = {k.x(), k.y(), k.z()};
  }
  return j;
}

// The numbers of array `key` of obstacle `where` (exactly `n`, finite).
std::vector<double> numbers(const std::string& path, const json& o, const char* key, std::size_t n,
                            const std::string& where) {
  const std::string field = where + "." + key;
  if (!o.contains(key) || !o.at(key).is_array() || o.at(key).size() != n) {
    fail(path, field + " must be an array of " + std::to_string(n) + " numbers");
  }
  std::vector<double> v;
  for (const json& x : o.at(key)) {
    if (!x.is_number() || !std::isfinite(x.get<double>())) {
      fail(path, field + " must be an array of " + std::to_string(n) + " finite numbers");
    }
    v.push_back(x.get<double>());
  }
  return v;
}

messages::ObstacleUpdate obstacle_from_json(const std::string& path, std::size_t index,
                                            const json& o) {
  std::string where = "obstacles[" + std::to_string(index) + "]";
  if (!o.is_object()) fail(path, where + " must be an object");
  for (const char* key : {"source", "id"}) {
    if (!o.contains(key) || !o.at(key).is_string()) fail(path, where + "." + key + " missing");
  }
  const std::string id = o.at("id").get<std::string>();
  if (id.empty()) fail(path, where + ".id is empty");
  where += " (\"" + id + "\")";
  if (!o.contains("shape") || !o.at("shape").is_string()) fail(path, where + ".shape missing");
  const auto kind = planning::shape_kind_from_name(o.at("shape").get<std::string>());
  if (!kind) {
    fail(path, where + ".shape \"" + o.at("shape").get<std::string>() +
                   "\" is not box, sphere, cylinder, capsule or mesh");
  }
  const std::vector<double> s = numbers(path, o, "size", 3, where);
  const std::vector<double> p = numbers(path, o, "position", 3, where);
  const std::vector<double> q = numbers(path, o, "quaternion", 4, where);
  messages::ObstacleUpdate u;
  u.source = o.at("source").get<std::string>();
  u.id = id;
  u.shape.kind = *kind;
  u.shape.size = Eigen::Vector3d(s[0], s[1], s[2]);
  if (*kind == collision::ShapeKind::kMesh) {
    if (!o.contains("mesh") || !o.at("mesh").is_string()) fail(path, where + ".mesh missing");
    const std::vector<double> k = numbers(path, o, "scale", 3, where);
    u.shape.mesh_path = o.at("mesh").get<std::string>();
    u.shape.mesh_scale = Eigen::Vector3d(k[0], k[1], k[2]);
    // Read again now, as when it arrived: a mesh gone since is refused here, not mid-plan.
    try {
      collision::ConvexShape hull(u.shape);
    } catch (const std::exception& e) {
      fail(path, where + ".mesh: " + e.what());
    }
  }
  if (std::string e = collision::range_error(u.shape); !e.empty()) fail(path, where + ": " + e);
  const Eigen::Vector3d position(p[0], p[1], p[2]);
  if (std::string e = collision::position_range_error(position); !e.empty()) {
    fail(path, where + ": " + e);
  }
  Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
  if (std::abs(rotation.norm() - 1) > 1e-6) fail(path, where + ".quaternion is not unit length");
  u.pose = Eigen::Translation3d(position) * rotation.normalized();
  return u;
}

}  // namespace

DaemonState read_state_file(const std::string& path, const std::string& robot,
                            const std::string& prefix) {
  std::ifstream in(path);
  if (!in) fail(path, "cannot be opened");
  json j;
  try {
    j = json::parse(in);
  } catch (const json::exception& e) {
    // parse_error (its what() gives the line and column), or out_of_range for 1e309.
    fail(path, std::string("is not valid JSON: ") + e.what());
  }
  if (!j.is_object() || j.value("format", json()) != kFormat) {
    fail(path, std::string("is not a kinographd state file (no \"format\": \"") + kFormat + "\")");
  }
  if (!j.contains("version") || !j.at("version").is_number_integer() ||
      j.at("version").get<int>() != kVersion) {
    fail(path, "is of version " + (j.contains("version") ? j.at("version").dump() : "?") +
                   "; this kinographd reads version " + std::to_string(kVersion));
  }
  DaemonState state;
  for (const auto& [key, out] : {std::pair{"robot", &state.robot}, {"prefix", &state.prefix}}) {
    if (!j.contains(key) || !j.at(key).is_string()) fail(path, std::string(key) + " missing");
    *out = j.at(key).get<std::string>();
  }
  if (state.robot != robot || state.prefix != prefix) {
    fail(path, "belongs to the daemon of robot \"" + state.robot + "\" on prefix " + state.prefix +
                   ", not robot \"" + robot + "\" on " + prefix +
                   ": give each daemon its own --state-file");
  }
  const json& bound = j.value("plan_ids_below", json());
  if (!bound.is_number_integer() || bound.get<int64_t>() < 1) {
    fail(path, "plan_ids_below must be a positive integer");
  }
  state.plan_ids_below = bound.get<int64_t>();
  const json& obstacles = j.value("obstacles", json::array());
  if (!obstacles.is_array()) fail(path, "obstacles must be an array");
  if (obstacles.size() > static_cast<std::size_t>(collision::kMaxObstacles)) {
    fail(path, std::to_string(obstacles.size()) + " obstacles, more than the " +
                   std::to_string(collision::kMaxObstacles) + " a world may hold");
  }
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    messages::ObstacleUpdate u = obstacle_from_json(path, i, obstacles[i]);
    const messages::ObstacleKey key{u.source, u.id};
    if (!state.obstacles.emplace(key, std::move(u)).second) {
      fail(path, "obstacles[" + std::to_string(i) + "]: \"" + key.second + "\" of source \"" +
                     key.first + "\" appears twice");
    }
  }
  return state;
}

void write_state_file(const std::string& path, const DaemonState& state) {
  json obstacles = json::array();
  for (const auto& [key, o] : state.obstacles) obstacles.push_back(obstacle_to_json(o));
  const json j = {{"format", kFormat},
                  {"version", kVersion},
                  {"robot", state.robot},
                  {"prefix", state.prefix},
                  {"plan_ids_below", state.plan_ids_below},
                  {"obstacles", obstacles}};
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << j.dump(1) << "\n";
    out.flush();
    if (!out) fail(tmp, "cannot be written");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    fail(path, "cannot be replaced by " + tmp);
  }
}

}  // namespace kinograph::daemon

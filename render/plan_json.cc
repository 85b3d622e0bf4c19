#include "render/plan_json.h"

#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "kinograph/dynamics/payload.h"

namespace kinograph::render {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw std::runtime_error(fmt::format("plan '{}': {}", source, what));
}

std::vector<double> numbers(const json& value, const std::string& source, const std::string& key) {
  if (!value.is_array()) fail(source, fmt::format("'{}' must be an array of numbers", key));
  std::vector<double> out;
  for (std::size_t i = 0; i < value.size(); ++i) {
    if (!value[i].is_number()) fail(source, fmt::format("'{}[{}]' is not a number", key, i));
    out.push_back(value[i].get<double>());
  }
  return out;
}

Eigen::Vector3d vector3(const json& value, const std::string& source, const std::string& key) {
  const std::vector<double> v = numbers(value, source, key);
  if (v.size() != 3) fail(source, fmt::format("'{}' must have 3 numbers, has {}", key, v.size()));
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

std::vector<Eigen::VectorXd> rows(const json& parent, const char* key, const std::string& source,
                                  std::size_t expected_rows, std::size_t width) {
  std::vector<Eigen::VectorXd> out;
  if (!parent.contains(key)) return out;
  const json& value = parent.at(key);
  if (!value.is_array()) fail(source, fmt::format("'{}' must be an array of arrays", key));
  if (value.size() != expected_rows) {
    fail(source, fmt::format("'{}' has {} rows but 't' has {}", key, value.size(), expected_rows));
  }
  for (std::size_t k = 0; k < value.size(); ++k) {
    const std::vector<double> row = numbers(value[k], source, fmt::format("{}[{}]", key, k));
    if (width != 0 && row.size() != width) {
      fail(source, fmt::format("'{}[{}]' has {} values, expected {}", key, k, row.size(), width));
    }
    out.push_back(
        Eigen::Map<const Eigen::VectorXd>(row.data(), static_cast<Eigen::Index>(row.size())));
  }
  return out;
}

json to_array(const Eigen::VectorXd& v) {
  return json(std::vector<double>(v.data(), v.data() + v.size()));
}

json to_rows(const std::vector<Eigen::VectorXd>& values) {
  json out = json::array();
  for (const Eigen::VectorXd& v : values) out.push_back(to_array(v));
  return out;
}

}  // namespace

PlanFile parse_plan_json(const json& j, const std::string& source) {
  PlanFile plan;
  plan.source = source;
  if (!j.is_object()) fail(source, "the top level must be a JSON object");
  if (j.contains("name") && j["name"].is_string()) plan.name = j["name"].get<std::string>();
  if (!j.contains("robot") || !j["robot"].is_object()) fail(source, "missing object 'robot'");
  const json& robot = j["robot"];
  if (!robot.contains("urdf") || !robot["urdf"].is_string()) {
    fail(source, "missing string 'robot.urdf'");
  }
  plan.urdf = robot["urdf"].get<std::string>();
  if (robot.contains("payload") && !robot["payload"].is_null()) {
    const json& p = robot["payload"];
    PlanPayload payload;
    if (!p.contains("frame") || !p["frame"].is_string()) {
      fail(source, "missing string 'robot.payload.frame'");
    }
    payload.frame = p["frame"].get<std::string>();
    if (!p.contains("mass") || !p["mass"].is_number()) {
      fail(source, "missing number 'robot.payload.mass'");
    }
    payload.mass = p["mass"].get<double>();
    if (!p.contains("size")) fail(source, "missing 'robot.payload.size'");
    payload.size = vector3(p["size"], source, "robot.payload.size");
    if (p.contains("offset")) payload.offset = vector3(p["offset"], source, "robot.payload.offset");
    plan.payload = payload;
  }
  if (j.contains("obstacles")) {
    if (!j["obstacles"].is_array()) fail(source, "'obstacles' must be an array");
    for (std::size_t i = 0; i < j["obstacles"].size(); ++i) {
      const json& o = j["obstacles"][i];
      const std::string where = fmt::format("obstacles[{}]", i);
      if (!o.is_object()) fail(source, fmt::format("'{}' must be an object", where));
      PlanObstacle obstacle;
      obstacle.id = o.value("id", where);
      obstacle.shape = o.value("shape", std::string("box"));
      static const std::vector<std::pair<std::string, std::size_t>> kSizes = {
          {"box", 3}, {"sphere", 1}, {"cylinder", 2}, {"capsule", 2}, {"mesh", 0}};
      const auto kind = std::find_if(kSizes.begin(), kSizes.end(),
                                     [&](const auto& k) { return k.first == obstacle.shape; });
      if (kind == kSizes.end()) {
        fail(source, fmt::format("'{}.shape' is '{}'; expected box, sphere, cylinder, capsule or "
                                 "mesh",
                                 where, obstacle.shape));
      }
      if (o.contains("size")) obstacle.size = numbers(o["size"], source, where + ".size");
      if (obstacle.size.size() < kind->second) {
        fail(source, fmt::format("'{}.size' needs {} numbers for a {}", where, kind->second,
                                 obstacle.shape));
      }
      if (obstacle.shape == "mesh") {
        if (!o.contains("mesh") || !o["mesh"].is_string()) {
          fail(source, fmt::format("'{}' is a mesh but has no string 'mesh'", where));
        }
        obstacle.mesh = o["mesh"].get<std::string>();
      }
      if (o.contains("position"))
        obstacle.position = vector3(o["position"], source, where + ".position");
      if (o.contains("quaternion")) {
        const std::vector<double> q = numbers(o["quaternion"], source, where + ".quaternion");
        if (q.size() != 4) fail(source, fmt::format("'{}.quaternion' must be [w,x,y,z]", where));
        obstacle.quaternion = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
        if (obstacle.quaternion.norm() < 1e-9) {
          fail(source, fmt::format("'{}.quaternion' is zero", where));
        }
        obstacle.quaternion.normalize();
      }
      if (o.contains("rgba")) {
        const std::vector<double> c = numbers(o["rgba"], source, where + ".rgba");
        if (c.size() != 4) fail(source, fmt::format("'{}.rgba' must have 4 numbers", where));
        obstacle.rgba = Eigen::Vector4d(c[0], c[1], c[2], c[3]);
      }
      plan.obstacles.push_back(obstacle);
    }
  }
  if (j.contains("joint_names")) {
    if (!j["joint_names"].is_array()) fail(source, "'joint_names' must be an array of strings");
    for (const json& name : j["joint_names"]) {
      if (!name.is_string()) fail(source, "'joint_names' must be an array of strings");
      plan.joint_names.push_back(name.get<std::string>());
    }
  }
  if (!j.contains("t")) fail(source, "missing array 't'");
  plan.t = numbers(j["t"], source, "t");
  if (!j.contains("q")) fail(source, "missing array 'q'");
  plan.q = rows(j, "q", source, plan.t.size(), plan.joint_names.size());
  const std::size_t width = plan.q.empty() ? plan.joint_names.size() : plan.q.front().size();
  for (std::size_t k = 0; k < plan.q.size(); ++k) {
    if (static_cast<std::size_t>(plan.q[k].size()) != width) {
      fail(source, fmt::format("'q[{}]' has {} values, 'q[0]' has {}", k, plan.q[k].size(), width));
    }
  }
  for (std::size_t k = 1; k < plan.t.size(); ++k) {
    if (plan.t[k] < plan.t[k - 1]) fail(source, fmt::format("'t[{}]' decreases", k));
  }
  plan.qd = rows(j, "qd", source, plan.t.size(), width);
  plan.qdd = rows(j, "qdd", source, plan.t.size(), width);
  plan.tau = rows(j, "tau", source, plan.t.size(), width);
  if (j.contains("limits") && j["limits"].contains("effort")) {
    plan.effort_limits = numbers(j["limits"]["effort"], source, "limits.effort");
    if (plan.effort_limits.size() != width) {
      fail(source, fmt::format("'limits.effort' has {} values for {} joints",
                               plan.effort_limits.size(), width));
    }
  }
  if (j.contains("stats")) plan.stats = j["stats"];
  if (j.contains("validation")) plan.validation = j["validation"];
  return plan;
}

PlanFile read_plan_json(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(fmt::format("cannot open plan file '{}'", path));
  json j;
  try {
    j = json::parse(in);
  } catch (const json::parse_error& e) {
    throw std::runtime_error(fmt::format("plan '{}' is not valid JSON: {}", path, e.what()));
  }
  return parse_plan_json(j, path);
}

json to_json(const PlanFile& plan) {
  json j;
  if (!plan.name.empty()) j["name"] = plan.name;
  j["robot"]["urdf"] = plan.urdf;
  if (plan.payload) {
    const PlanPayload& p = *plan.payload;
    j["robot"]["payload"] = {{"frame", p.frame},
                             {"mass", p.mass},
                             {"size", {p.size.x(), p.size.y(), p.size.z()}},
                             {"offset", {p.offset.x(), p.offset.y(), p.offset.z()}}};
  }
  j["obstacles"] = json::array();
  for (const PlanObstacle& o : plan.obstacles) {
    json oj = {
        {"id", o.id},
        {"shape", o.shape},
        {"size", o.size},
        {"position", {o.position.x(), o.position.y(), o.position.z()}},
        {"quaternion", {o.quaternion.w(), o.quaternion.x(), o.quaternion.y(), o.quaternion.z()}}};
    if (!o.mesh.empty()) oj["mesh"] = o.mesh;
    if (o.rgba) oj["rgba"] = {o.rgba->x(), o.rgba->y(), o.rgba->z(), o.rgba->w()};
    j["obstacles"].push_back(oj);
  }
  j["joint_names"] = plan.joint_names;
  j["t"] = plan.t;
  j["q"] = to_rows(plan.q);
  if (!plan.qd.empty()) j["qd"] = to_rows(plan.qd);
  if (!plan.qdd.empty()) j["qdd"] = to_rows(plan.qdd);
  if (!plan.tau.empty()) j["tau"] = to_rows(plan.tau);
  if (!plan.effort_limits.empty()) j["limits"]["effort"] = plan.effort_limits;
  j["stats"] = plan.stats;
  j["validation"] = plan.validation;
  return j;
}

void write_plan_json(const PlanFile& plan, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(fmt::format("cannot write plan file '{}'", path));
  out << to_json(plan).dump(1) << "\n";
  if (!out) throw std::runtime_error(fmt::format("error while writing plan file '{}'", path));
}

std::string resolve_plan_path(const std::string& path, const std::string& plan_source) {
  const fs::path p(path);
  if (p.is_absolute()) return path;
  std::vector<fs::path> candidates = {fs::current_path() / p};
  if (!plan_source.empty()) candidates.push_back(fs::absolute(plan_source).parent_path() / p);
  candidates.push_back(fs::path(KINOGRAPH_SOURCE_DIR) / p);
  for (const fs::path& c : candidates) {
    if (fs::exists(c)) return fs::weakly_canonical(c).string();
  }
  throw std::runtime_error(fmt::format(
      "plan '{}': cannot find '{}' (looked in the working directory, next to the plan and in {})",
      plan_source, path, KINOGRAPH_SOURCE_DIR));
}

dynamics::Model load_plan_model(const PlanFile& plan) {
  dynamics::Model model =
      dynamics::Model::from_urdf_file(resolve_plan_path(plan.urdf, plan.source));
  if (plan.payload) {
    const PlanPayload& p = *plan.payload;
    Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
    offset.translation() = p.offset;
    try {
      model = dynamics::attach_box_payload(model, p.frame, p.mass, p.size, offset);
    } catch (const std::exception& e) {
      fail(plan.source, fmt::format("robot.payload: {}", e.what()));
    }
  }
  return model;
}

std::vector<dynamics::Geometry> plan_obstacles(const PlanFile& plan) {
  using Shape = dynamics::Geometry::Shape;
  std::vector<dynamics::Geometry> out;
  for (const PlanObstacle& o : plan.obstacles) {
    dynamics::Geometry g;
    g.body = -1;
    g.link_name = o.id;
    g.origin = Eigen::Isometry3d::Identity();
    g.origin.linear() = o.quaternion.toRotationMatrix();
    g.origin.translation() = o.position;
    // Plans carry no colours by default: obstacles get one blue that no robot part uses.
    g.rgba = o.rgba.value_or(Eigen::Vector4d(0.30, 0.55, 0.85, 1.0));
    const auto size = [&](std::size_t i) { return i < o.size.size() ? o.size[i] : 0.0; };
    if (o.shape == "box") {
      g.shape = Shape::kBox;
      g.size = Eigen::Vector3d(size(0), size(1), size(2));
    } else if (o.shape == "sphere") {
      g.shape = Shape::kSphere;
      g.size = Eigen::Vector3d(size(0), 0, 0);
    } else if (o.shape == "cylinder" || o.shape == "capsule") {
      g.shape = o.shape == "cylinder" ? Shape::kCylinder : Shape::kCapsule;
      g.size = Eigen::Vector3d(size(0), size(1), 0);
    } else {
      g.shape = Shape::kMesh;
      g.mesh_path = resolve_plan_path(o.mesh, plan.source);
      if (o.size.size() == 3) g.mesh_scale = Eigen::Vector3d(o.size[0], o.size[1], o.size[2]);
    }
    out.push_back(g);
  }
  return out;
}

Trajectory plan_trajectory(const PlanFile& plan, const dynamics::Model& model) {
  Trajectory trajectory;
  trajectory.t = plan.t;
  std::vector<int> column(model.nq());
  for (int i = 0; i < model.nq(); ++i) column[i] = i;
  if (!plan.joint_names.empty()) {
    for (int i = 0; i < model.nq(); ++i) {
      const auto it =
          std::find(plan.joint_names.begin(), plan.joint_names.end(), model.bodies[i].joint_name);
      if (it == plan.joint_names.end()) {
        fail(plan.source,
             fmt::format("robot joint '{}' is not in 'joint_names'", model.bodies[i].joint_name));
      }
      column[i] = static_cast<int>(it - plan.joint_names.begin());
    }
  }
  for (std::size_t k = 0; k < plan.q.size(); ++k) {
    if (plan.joint_names.empty() && plan.q[k].size() != model.nq()) {
      fail(plan.source, fmt::format("'q[{}]' has {} values, the robot has {} joints", k,
                                    plan.q[k].size(), model.nq()));
    }
    Eigen::VectorXd q(model.nq());
    for (int i = 0; i < model.nq(); ++i) q[i] = plan.q[k][column[i]];
    trajectory.q.push_back(q);
  }
  return trajectory;
}

}  // namespace kinograph::render

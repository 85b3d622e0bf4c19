#include "kinograph/planning/io/scene.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <system_error>

#include "kinograph/collision/obstacle.h"
#include "kinograph/collision/shape.h"
#include "kinograph/dynamics/base_placement.h"
#include "kinograph/dynamics/payload.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/clearance_world.h"
#include "kinograph/planning/io/data_dir.h"
#include "kinograph/planning/io/number_text.h"
#include "kinograph/planning/io/srdf.h"
#include "kinograph/planning/io/yaml_reader.h"

namespace kinograph::planning {
namespace {

namespace fs = std::filesystem;

std::string format_error(const std::string& file, const std::string& key, int line,
                         const std::string& message) {
  std::ostringstream os;
  os << "scene '" << (file.empty() ? "<text>" : file) << "'";
  if (line > 0) os << " line " << line;
  if (!key.empty()) os << ": '" << key << "'";
  os << ": " << message;
  return os.str();
}

using yaml::index_key;
using yaml::join;
using yaml::Reader;

std::string anchor_of(const std::string& source) {
  if (source.empty()) return fs::current_path().string();
  return fs::absolute(fs::path(source)).parent_path().string();
}

Eigen::Isometry3d make_pose(const Eigen::Vector3d& position, const Eigen::Matrix3d& rotation) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation;
  pose.translation() = position;
  return pose;
}

class SceneParser {
 public:
  explicit SceneParser(std::string source, yaml::KeyPathMap key_path = {})
      : r_(source, std::move(key_path)), source_(std::move(source)) {
    anchor_ = anchor_of(source_);
  }

  Scene parse(const YAML::Node& root) {
    Scene scene;
    scene.source = source_;
    if (!root.IsDefined() || root.IsNull()) r_.fail(root, "", "the file is empty");
    r_.expect_map(root, "",
                  {"name", "robot", "horizon", "steps", "start", "goal", "obstacles", "limits",
                   "unactuated", "task_constraints", "objectives", "planner", "camera",
                   "self_collision", "allowed_collisions", "floor"});
    Problem& problem = scene.problem;
    problem.name = root["name"] ? r_.string(root["name"], "name")
                                : (source_.empty() ? "scene" : fs::path(source_).stem().string());
    dynamics::Model model = parse_robot(root, scene);
    if (const YAML::Node limits = root["limits"]) parse_limits(limits, scene, model);
    if (const YAML::Node passive = root["unactuated"]) parse_unactuated(passive, scene, model);
    problem.model = std::make_shared<const dynamics::Model>(std::move(model));
    const dynamics::Model& m = *problem.model;

    problem.horizon = r_.positive(r_.required(root, "", "horizon"), "horizon");
    const YAML::Node steps = r_.required(root, "", "steps");
    problem.steps = r_.integer(steps, "steps");
    if (problem.steps < 1) r_.fail(steps, "steps", "must be at least 1");
    if (problem.steps > kMaxSceneSteps) {
      r_.fail(steps, "steps", "must be at most " + std::to_string(kMaxSceneSteps));
    }

    const YAML::Node start = r_.required(root, "", "start");
    r_.expect_map(start, "start", {"q", "qd"});
    problem.start_q = r_.vector(r_.required(start, "start", "q"), "start.q", m.nq());
    problem.start_qd = start["qd"] ? r_.vector(start["qd"], "start.qd", m.nq())
                                   : Eigen::VectorXd::Zero(m.nq()).eval();

    parse_goal(r_.required(root, "", "goal"), problem.goal, m);
    if (const YAML::Node obstacles = root["obstacles"]) parse_obstacles(obstacles, scene);
    parse_self_and_floor(root, scene);
    if (const YAML::Node tasks = root["task_constraints"]) parse_tasks(tasks, problem, m);
    if (const YAML::Node objectives = root["objectives"]) {
      parse_objectives(objectives, problem.objectives);
    }
    if (const YAML::Node planner = root["planner"]) parse_planner(planner, scene.planner);
    if (const YAML::Node camera = root["camera"]) {
      // Read by the renderer (render/scene_camera.h); here only its form is checked.
      if (!camera.IsMap()) r_.fail(camera, "camera", "must be a map");
    }
    return scene;
  }

 private:
  std::string resolve(const YAML::Node& node, const std::string& key, const std::string& path) {
    const std::optional<std::string> resolved = resolve_scene_path(path, anchor_);
    if (!resolved) {
      r_.fail(node, key,
              "file '" + path + "' not found (looked next to the scene and in " +
                  describe_data_dirs() + ")");
    }
    return *resolved;
  }

  dynamics::Model parse_robot(const YAML::Node& root, Scene& scene) {
    const YAML::Node robot = r_.required(root, "", "robot");
    r_.expect_map(robot, "robot", {"urdf", "payload", "srdf", "base"});
    const YAML::Node urdf = r_.required(robot, "robot", "urdf");
    scene.urdf = r_.string(urdf, "robot.urdf");
    scene.urdf_path = resolve(urdf, "robot.urdf", scene.urdf);
    dynamics::Model model;
    try {
      model = dynamics::Model::from_urdf_file(scene.urdf_path);
    } catch (const std::exception& e) {
      r_.fail(urdf, "robot.urdf", std::string("cannot load the robot: ") + e.what());
    }
    if (const YAML::Node b = robot["base"]) {
      r_.expect_map(b, "robot.base", {"position", "rpy", "quaternion"});
      const Eigen::Vector3d position =
          b["position"] ? r_.vector3(b["position"], "robot.base.position")
                        : Eigen::Vector3d::Zero().eval();
      if (const std::string e = collision::position_range_error(position); !e.empty()) {
        r_.fail(b["position"], "robot.base.position", e);
      }
      scene.base =
          make_pose(position, r_.rotation(b, "robot.base").value_or(Eigen::Matrix3d::Identity()));
      model = dynamics::place_base(model, scene.base);
    }
    if (const YAML::Node p = robot["payload"]) {
      r_.expect_map(p, "robot.payload", {"frame", "mass", "size", "offset"});
      PayloadSpec payload;
      payload.frame = r_.string(r_.required(p, "robot.payload", "frame"), "robot.payload.frame");
      payload.mass = r_.non_negative(r_.required(p, "robot.payload", "mass"), "robot.payload.mass");
      payload.size = r_.vector3(r_.required(p, "robot.payload", "size"), "robot.payload.size");
      if (payload.size.minCoeff() <= 0) r_.fail(p["size"], "robot.payload.size", "must be > 0");
      if (p["offset"]) payload.offset = r_.vector3(p["offset"], "robot.payload.offset");
      try {
        model =
            dynamics::attach_box_payload(model, payload.frame, payload.mass, payload.size,
                                         make_pose(payload.offset, Eigen::Matrix3d::Identity()));
      } catch (const std::exception& e) {
        r_.fail(p, "robot.payload", std::string("cannot attach: ") + e.what());
      }
      scene.payload = payload;
    }
    return model;
  }

  // robot.srdf, allowed_collisions, self_collision and floor: what the robot must clear
  // besides the obstacles.
  void parse_self_and_floor(const YAML::Node& root, Scene& scene) {
    SelfAndFloor& sf = scene.problem.self_and_floor;
    const dynamics::Model& m = *scene.problem.model;
    if (const YAML::Node srdf = root["robot"]["srdf"]) {
      scene.srdf = r_.string(srdf, "robot.srdf");
      scene.srdf_path = resolve(srdf, "robot.srdf", scene.srdf);
      try {
        for (const auto& pair : allowed_body_pairs(m, load_srdf(scene.srdf_path), scene.srdf_path))
          sf.allowed_pairs.push_back(pair);
      } catch (const SrdfError& e) {
        r_.fail(srdf, "robot.srdf", e.what());
      }
    }
    if (const YAML::Node list = root["allowed_collisions"]) {
      if (!list.IsSequence()) r_.fail(list, "allowed_collisions", "must be a list of [link, link]");
      for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string key = index_key("allowed_collisions", i);
        if (!list[i].IsSequence() || list[i].size() != 2)
          r_.fail(list[i], key, "must be [link, link]");
        std::pair<std::string, std::string> names;
        int body[2];
        for (std::size_t j = 0; j < 2; ++j) {
          const std::string k = index_key(key, j);
          const std::string link = r_.string(list[i][j], k);
          check_frame(list[i][j], k, link, m);
          body[j] = m.frames[m.frame_index(link)].body;
          (j == 0 ? names.first : names.second) = link;
        }
        sf.allowed_pairs.emplace_back(body[0], body[1]);
        scene.allowed_collisions.push_back(std::move(names));
      }
    }
    if (root["self_collision"])
      sf.self_collision = r_.boolean(root["self_collision"], "self_collision");
    sf.floor = mounting_floor(m);
    if (const YAML::Node floor = root["floor"]) {
      r_.expect_map(floor, "floor", {"enabled", "height"});
      const bool enabled = !floor["enabled"] || r_.boolean(floor["enabled"], "floor.enabled");
      const double height = floor["height"] ? r_.finite(floor["height"], "floor.height") : 0.0;
      if (floor["height"] && !enabled) {
        r_.fail(floor["height"], "floor.height", "a disabled floor takes no height");
      }
      sf.floor = enabled ? std::optional<double>(height) : std::nullopt;
    }
  }

  void parse_limits(const YAML::Node& limits, Scene& scene, dynamics::Model& model) {
    if (!limits.IsMap()) r_.fail(limits, "limits", "must be a map from joint name to limits");
    std::set<std::string> seen;
    for (const auto& entry : limits) {
      const std::string joint = entry.first.Scalar();
      const std::string key = join("limits", joint);
      if (!seen.insert(joint).second) r_.fail(entry.first, key, "duplicate joint");
      int body = -1;
      for (int i = 0; i < model.nq(); ++i) {
        if (model.bodies[i].joint_name == joint) body = i;
      }
      if (body < 0) r_.fail(entry.first, key, "no such joint in the robot '" + model.name + "'");
      const YAML::Node& node = entry.second;
      r_.expect_map(node, key, {"lower", "upper", "velocity", "effort", "acceleration"});
      LimitOverride o;
      dynamics::JointLimits& l = model.bodies[body].limits;
      if (node["lower"]) l.lower = *(o.lower = r_.number(node["lower"], join(key, "lower")));
      if (node["upper"]) l.upper = *(o.upper = r_.number(node["upper"], join(key, "upper")));
      if (!(l.lower <= l.upper)) r_.fail(node, key, "lower limit is above the upper limit");
      const auto bound = [&](const char* name, std::optional<double>& slot, double& limit) {
        if (!node[name]) return;
        const double v = r_.number(node[name], join(key, name));
        if (!(v >= 0)) r_.fail(node[name], join(key, name), "must be >= 0 (.inf for none)");
        slot = v;
        limit = v;
      };
      bound("velocity", o.velocity, l.velocity);
      bound("effort", o.effort, l.effort);
      bound("acceleration", o.acceleration, l.acceleration);
      if (o.effort && *o.effort == 0) {
        r_.fail(node["effort"], join(key, "effort"),
                "0 would forbid any torque; list a passive joint under 'unactuated' instead");
      }
      scene.limits.emplace_back(joint, o);
    }
  }

  // The passive joints: URDF has no way to say a joint has no motor.
  void parse_unactuated(const YAML::Node& list, Scene& scene, dynamics::Model& model) {
    if (!list.IsSequence()) r_.fail(list, "unactuated", "must be a list of joint names");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string key = index_key("unactuated", i);
      const std::string joint = r_.string(list[i], key);
      int body = -1;
      for (int b = 0; b < model.nq(); ++b) {
        if (model.bodies[b].joint_name == joint) body = b;
      }
      if (body < 0)
        r_.fail(list[i], key, "no joint '" + joint + "' in the robot '" + model.name + "'");
      for (const std::string& other : scene.unactuated) {
        if (other == joint) r_.fail(list[i], key, "joint '" + joint + "' is listed twice");
      }
      model.bodies[body].actuated = false;
      scene.unactuated.push_back(joint);
    }
  }

  void parse_goal(const YAML::Node& node, Goal& goal, const dynamics::Model& model) {
    r_.expect_map(node, "goal", {"q", "frame", "position", "rpy", "quaternion", "position_only"});
    if (node["q"]) {
      for (const char* k : {"frame", "position", "rpy", "quaternion", "position_only"}) {
        if (node[k]) r_.fail(node[k], join("goal", k), "a joint goal (goal.q) takes no pose keys");
      }
      goal.kind = Goal::Kind::kJoint;
      goal.q = r_.vector(node["q"], "goal.q", model.nq());
      return;
    }
    goal.kind = Goal::Kind::kPose;
    const YAML::Node frame = node["frame"];
    if (!frame) r_.fail(node, "goal", "needs either 'q' (joint goal) or 'frame' (pose goal)");
    goal.frame = r_.string(frame, "goal.frame");
    check_frame(frame, "goal.frame", goal.frame, model);
    goal.position_only =
        node["position_only"] && r_.boolean(node["position_only"], "goal.position_only");
    const Eigen::Vector3d position =
        r_.vector3(r_.required(node, "goal", "position"), "goal.position");
    const std::optional<Eigen::Matrix3d> rotation = r_.rotation(node, "goal");
    if (!rotation && !goal.position_only) {
      r_.fail(node, "goal", "a pose goal needs 'rpy' or 'quaternion' (or position_only: true)");
    }
    goal.pose = make_pose(position, rotation.value_or(Eigen::Matrix3d::Identity()));
  }

  void check_frame(const YAML::Node& node, const std::string& key, const std::string& frame,
                   const dynamics::Model& model) {
    for (const dynamics::Frame& f : model.frames) {
      if (f.name == frame) return;
    }
    r_.fail(node, key, "no frame '" + frame + "' in the robot '" + model.name + "'");
  }

  void parse_obstacles(const YAML::Node& list, Scene& scene) {
    if (!list.IsSequence()) r_.fail(list, "obstacles", "must be a list");
    if (list.size() > static_cast<std::size_t>(collision::kMaxObstacles)) {
      r_.fail(list, "obstacles",
              "holds " + std::to_string(list.size()) + " obstacles, more than the " +
                  std::to_string(collision::kMaxObstacles) + " a world may hold");
    }
    for (std::size_t i = 0; i < list.size(); ++i) {
      const YAML::Node node = list[i];
      const std::string key = index_key("obstacles", i);
      r_.expect_map(
          node, key,
          {"id", "shape", "size", "mesh", "scale", "position", "rpy", "quaternion", "motion"});
      const std::string name = r_.string(r_.required(node, key, "id"), join(key, "id"));
      for (const std::string& other : scene.obstacle_names) {
        if (other == name)
          r_.fail(node["id"], join(key, "id"), "duplicate obstacle id '" + name + "'");
      }
      collision::Obstacle obstacle;
      obstacle.id = static_cast<int>(scene.obstacle_names.size());
      obstacle.shape = parse_shape(node, key);
      if (const std::string e = collision::range_error(obstacle.shape); !e.empty()) {
        const char* k = obstacle.shape.kind == collision::ShapeKind::kMesh ? "scale" : "size";
        r_.fail(node[k], join(key, k), "obstacle '" + name + "': " + e);
      }
      const Eigen::Vector3d position = node["position"]
                                           ? r_.vector3(node["position"], join(key, "position"))
                                           : Eigen::Vector3d::Zero().eval();
      if (const std::string e = collision::position_range_error(position); !e.empty()) {
        r_.fail(node["position"], join(key, "position"), "obstacle '" + name + "': " + e);
      }
      obstacle.pose =
          make_pose(position, r_.rotation(node, key).value_or(Eigen::Matrix3d::Identity()));
      if (const YAML::Node motion = node["motion"]) {
        obstacle.trajectory = parse_motion(motion, join(key, "motion"));
      }
      scene.obstacle_names.push_back(name);
      scene.problem.obstacles.push_back(std::move(obstacle));
    }
  }

  collision::Shape parse_shape(const YAML::Node& node, const std::string& key) {
    const YAML::Node kind_node = r_.required(node, key, "shape");
    const std::string kind = r_.string(kind_node, join(key, "shape"));
    const std::string size_key = join(key, "size");
    const auto size = [&](int n) {
      const Eigen::VectorXd s = r_.vector(r_.required(node, key, "size"), size_key, n);
      if (s.minCoeff() <= 0) r_.fail(node["size"], size_key, "every size must be > 0");
      return s;
    };
    const auto no_key = [&](const char* k) {
      if (node[k])
        r_.fail(node[k], join(key, k), "only a mesh obstacle takes '" + std::string(k) + "'");
    };
    if (kind == "mesh") {
      if (node["size"]) r_.fail(node["size"], size_key, "a mesh takes 'scale', not 'size'");
      const YAML::Node mesh = r_.required(node, key, "mesh");
      const std::string path = resolve(mesh, join(key, "mesh"), r_.string(mesh, join(key, "mesh")));
      Eigen::Vector3d scale = Eigen::Vector3d::Ones();
      if (node["scale"]) scale = r_.vector3(node["scale"], join(key, "scale"));
      if (scale.minCoeff() <= 0) r_.fail(node["scale"], join(key, "scale"), "must be > 0");
      return collision::Shape::mesh(path, scale);
    }
    no_key("mesh");
    no_key("scale");
    if (kind == "box") {
      const Eigen::VectorXd s = size(3);
      return collision::Shape::box(s[0], s[1], s[2]);
    }
    if (kind == "sphere") return collision::Shape::sphere(size(1)[0]);
    if (kind == "cylinder") {
      const Eigen::VectorXd s = size(2);
      return collision::Shape::cylinder(s[0], s[1]);
    }
    if (kind == "capsule") {
      const Eigen::VectorXd s = size(2);
      return collision::Shape::capsule(s[0], s[1]);
    }
    r_.fail(kind_node, join(key, "shape"),
            "'" + kind + "' is not one of box, sphere, cylinder, capsule, mesh");
  }

  collision::PoseTrajectory parse_motion(const YAML::Node& list, const std::string& key) {
    if (!list.IsSequence() || list.size() == 0) {
      r_.fail(list, key, "must be a non-empty list of {t, position, rpy|quaternion}");
    }
    std::vector<double> times;
    std::vector<Eigen::Isometry3d> poses;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const YAML::Node node = list[i];
      const std::string k = index_key(key, i);
      r_.expect_map(node, k, {"t", "position", "rpy", "quaternion"});
      const double t = r_.finite(r_.required(node, k, "t"), join(k, "t"));
      if (!times.empty() && !(t > times.back())) {
        r_.fail(node["t"], join(k, "t"), "times must increase strictly");
      }
      times.push_back(t);
      poses.push_back(make_pose(r_.vector3(r_.required(node, k, "position"), join(k, "position")),
                                r_.rotation(node, k).value_or(Eigen::Matrix3d::Identity())));
    }
    return collision::PoseTrajectory(std::move(times), std::move(poses));
  }

  void parse_tasks(const YAML::Node& list, Problem& problem, const dynamics::Model& model) {
    if (!list.IsSequence()) r_.fail(list, "task_constraints", "must be a list");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const YAML::Node node = list[i];
      const std::string key = index_key("task_constraints", i);
      r_.expect_map(node, key,
                    {"frame", "orientation_only", "position", "rpy", "quaternion", "tolerance"});
      TaskConstraint task;
      const YAML::Node frame = r_.required(node, key, "frame");
      task.frame = r_.string(frame, join(key, "frame"));
      check_frame(frame, join(key, "frame"), task.frame, model);
      if (node["orientation_only"]) {
        task.orientation_only = r_.boolean(node["orientation_only"], join(key, "orientation_only"));
      }
      const std::optional<Eigen::Matrix3d> rotation = r_.rotation(node, key);
      if (!rotation) r_.fail(node, key, "needs the target orientation ('rpy' or 'quaternion')");
      Eigen::Vector3d position = Eigen::Vector3d::Zero();
      if (node["position"]) {
        if (task.orientation_only) {
          r_.fail(node["position"], join(key, "position"),
                  "an orientation-only constraint takes no position");
        }
        position = r_.vector3(node["position"], join(key, "position"));
      } else if (!task.orientation_only) {
        r_.fail(node, key, "a full-pose constraint (orientation_only: false) needs 'position'");
      }
      task.target = make_pose(position, *rotation);
      if (node["tolerance"])
        task.tolerance = r_.positive(node["tolerance"], join(key, "tolerance"));
      problem.task_constraints.push_back(task);
    }
  }

  void parse_objectives(const YAML::Node& node, Objectives& o) {
    r_.expect_map(node, "objectives",
                  {"min_torque", "qc", "collision_epsilon", "limit_epsilon", "collision_substeps",
                   "self_collision_epsilon", "limit_substeps"});
    if (node["min_torque"]) {
      o.min_torque = r_.non_negative(node["min_torque"], "objectives.min_torque");
    }
    if (node["qc"]) o.qc = r_.positive(node["qc"], "objectives.qc");
    if (node["collision_epsilon"]) {
      o.collision_epsilon =
          r_.non_negative(node["collision_epsilon"], "objectives.collision_epsilon");
    }
    if (node["limit_epsilon"]) {
      o.limit_epsilon = r_.non_negative(node["limit_epsilon"], "objectives.limit_epsilon");
    }
    if (node["self_collision_epsilon"]) {
      o.self_collision_epsilon =
          r_.non_negative(node["self_collision_epsilon"], "objectives.self_collision_epsilon");
    }
    if (node["collision_substeps"]) {
      o.collision_substeps =
          r_.integer(node["collision_substeps"], "objectives.collision_substeps");
      if (o.collision_substeps < 0) {
        r_.fail(node["collision_substeps"], "objectives.collision_substeps", "must be >= 0");
      }
      if (o.collision_substeps > kMaxSceneSubsteps) {
        r_.fail(node["collision_substeps"], "objectives.collision_substeps",
                "must be at most " + std::to_string(kMaxSceneSubsteps));
      }
    }
    if (node["limit_substeps"]) {
      o.limit_substeps = r_.integer(node["limit_substeps"], "objectives.limit_substeps");
      if (o.limit_substeps < 0) {
        r_.fail(node["limit_substeps"], "objectives.limit_substeps", "must be >= 0");
      }
      if (o.limit_substeps > kMaxSceneSubsteps) {
        r_.fail(node["limit_substeps"], "objectives.limit_substeps",
                "must be at most " + std::to_string(kMaxSceneSubsteps));
      }
    }
  }

  void parse_planner(const YAML::Node& node, PlannerSpec& planner) {
    r_.expect_map(node, "planner", {"formulation", "init", "warm"});
    if (node["formulation"]) {
      planner.formulation = r_.string(node["formulation"], "planner.formulation");
      if (!formulation_from_name(planner.formulation)) {
        r_.fail(node["formulation"], "planner.formulation", "must be 'condensed' or 'dfg'");
      }
    }
    if (node["init"]) {
      planner.init = r_.string(node["init"], "planner.init");
      if (planner.init != "L" && planner.init != "W") {
        r_.fail(node["init"], "planner.init", "must be 'L' (straight line) or 'W' (warm start)");
      }
    }
    if (node["warm"]) {
      planner.warm = resolve(node["warm"], "planner.warm", r_.string(node["warm"], "planner.warm"));
    }
    if (planner.init == "W" && planner.warm.empty()) {
      r_.fail(node, "planner.warm", "init W needs a plan file to warm-start from");
    }
  }

  Reader r_;
  std::string source_, anchor_;
};

// ---- writing ----

void emit_vector(YAML::Emitter& out, const Eigen::VectorXd& v) {
  out << YAML::Flow << YAML::BeginSeq;
  for (Eigen::Index i = 0; i < v.size(); ++i) out << v[i];
  out << YAML::EndSeq;
}

void emit_rotation(YAML::Emitter& out, const Eigen::Matrix3d& r) {
  const Eigen::Quaterniond q(r);
  out << YAML::Key << "quaternion" << YAML::Value;
  emit_vector(out, Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()));
}

void emit_pose(YAML::Emitter& out, const Eigen::Isometry3d& pose) {
  out << YAML::Key << "position" << YAML::Value;
  emit_vector(out, pose.translation());
  emit_rotation(out, pose.linear());
}

}  // namespace

SceneError::SceneError(std::string file, std::string key, int line, const std::string& message)
    : std::runtime_error(format_error(file, key, line, message)),
      file_(std::move(file)),
      key_(std::move(key)),
      line_(line) {}

std::string shape_kind_name(collision::ShapeKind kind) {
  switch (kind) {
    case collision::ShapeKind::kSphere:
      return "sphere";
    case collision::ShapeKind::kBox:
      return "box";
    case collision::ShapeKind::kCylinder:
      return "cylinder";
    case collision::ShapeKind::kCapsule:
      return "capsule";
    case collision::ShapeKind::kMesh:
      return "mesh";
  }
  return "box";
}

std::optional<collision::ShapeKind> shape_kind_from_name(const std::string& name) {
  for (collision::ShapeKind kind :
       {collision::ShapeKind::kSphere, collision::ShapeKind::kBox, collision::ShapeKind::kCylinder,
        collision::ShapeKind::kCapsule, collision::ShapeKind::kMesh}) {
    if (shape_kind_name(kind) == name) return kind;
  }
  return std::nullopt;
}

std::optional<Formulation> formulation_from_name(const std::string& name) {
  for (Formulation f : {Formulation::kCondensed, Formulation::kDynamicFactorGraph}) {
    if (to_string(f) == name) return f;
  }
  return std::nullopt;
}

std::optional<std::string> resolve_scene_path(const std::string& path,
                                              const std::string& anchor_dir) {
  // A path the system cannot even look up (a name too long, a component not a directory) is
  // not found: the throwing overloads would escape the readers as a filesystem_error.
  std::error_code ec;
  const fs::path p(path);
  if (p.is_absolute()) {
    if (fs::exists(p, ec)) return p.lexically_normal().string();
    return std::nullopt;
  }
  std::vector<fs::path> bases{fs::path(anchor_dir)};
  for (const fs::path& dir : data_dirs()) bases.push_back(dir);
  for (const fs::path& base : bases) {
    const fs::path candidate = base / p;
    if (!fs::exists(candidate, ec)) continue;
    const fs::path canonical = fs::weakly_canonical(candidate, ec);
    if (!ec) return canonical.string();
  }
  return std::nullopt;
}

Scene parse_scene(const std::string& yaml, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw SceneError(source, "", e.mark.is_null() ? 0 : e.mark.line + 1,
                     "not valid YAML: " + e.msg);
  }
  return SceneParser(source).parse(root);
}

Scene yaml::parse_scene_tree(const YAML::Node& root, const std::string& source,
                             KeyPathMap key_path) {
  return SceneParser(source, std::move(key_path)).parse(root);
}

Scene load_scene(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw SceneError(path, "", 0, "cannot open the file");
  std::stringstream text;
  text << in.rdbuf();
  return parse_scene(text.str(), path);
}

namespace {

// The limits section: every overridden limit of every joint.
void emit_limits(YAML::Emitter& out, const Scene& scene) {
  if (!scene.limits.empty()) {
    out << YAML::Key << "limits" << YAML::Value << YAML::BeginMap;
    for (const auto& [joint, o] : scene.limits) {
      out << YAML::Key << joint << YAML::Value << YAML::BeginMap;
      const auto put = [&](const char* name, const std::optional<double>& v) {
        if (v) out << YAML::Key << name << YAML::Value << *v;
      };
      put("lower", o.lower);
      put("upper", o.upper);
      put("velocity", o.velocity);
      put("effort", o.effort);
      put("acceleration", o.acceleration);
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  if (!scene.unactuated.empty()) {
    out << YAML::Key << "unactuated" << YAML::Value << YAML::Flow << scene.unactuated;
  }
}

// The obstacles section, in the problem's order, named as in the file.
void emit_obstacles(YAML::Emitter& out, const Scene& scene) {
  const Problem& p = scene.problem;
  if (!p.obstacles.empty()) {
    out << YAML::Key << "obstacles" << YAML::Value << YAML::BeginSeq;
    for (std::size_t i = 0; i < p.obstacles.size(); ++i) {
      const collision::Obstacle& o = p.obstacles[i];
      out << YAML::BeginMap;
      out << YAML::Key << "id" << YAML::Value
          << (i < scene.obstacle_names.size() ? scene.obstacle_names[i] : std::to_string(o.id));
      out << YAML::Key << "shape" << YAML::Value << shape_kind_name(o.shape.kind);
      switch (o.shape.kind) {
        case collision::ShapeKind::kBox:
          out << YAML::Key << "size" << YAML::Value;
          emit_vector(out, o.shape.size);
          break;
        case collision::ShapeKind::kSphere:
          out << YAML::Key << "size" << YAML::Value;
          emit_vector(out, o.shape.size.head<1>());
          break;
        case collision::ShapeKind::kCylinder:
        case collision::ShapeKind::kCapsule:
          out << YAML::Key << "size" << YAML::Value;
          emit_vector(out, o.shape.size.head<2>());
          break;
        case collision::ShapeKind::kMesh:
          out << YAML::Key << "mesh" << YAML::Value << o.shape.mesh_path;
          out << YAML::Key << "scale" << YAML::Value;
          emit_vector(out, o.shape.mesh_scale);
          break;
      }
      emit_pose(out, o.pose);
      if (o.is_moving()) {
        out << YAML::Key << "motion" << YAML::Value << YAML::BeginSeq;
        for (std::size_t k = 0; k < o.trajectory.times().size(); ++k) {
          out << YAML::BeginMap << YAML::Key << "t" << YAML::Value << o.trajectory.times()[k];
          emit_pose(out, o.trajectory.poses()[k]);
          out << YAML::EndMap;
        }
        out << YAML::EndSeq;
      }
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
}

// self_collision, allowed_collisions (the scene's own; the SRDF's stay in its file) and floor.
void emit_self_and_floor(YAML::Emitter& out, const Scene& scene) {
  const SelfAndFloor& sf = scene.problem.self_and_floor;
  out << YAML::Key << "self_collision" << YAML::Value << sf.self_collision;
  if (!scene.allowed_collisions.empty()) {
    out << YAML::Key << "allowed_collisions" << YAML::Value << YAML::BeginSeq;
    for (const auto& [a, b] : scene.allowed_collisions) {
      out << YAML::Flow << YAML::BeginSeq << a << b << YAML::EndSeq;
    }
    out << YAML::EndSeq;
  }
  out << YAML::Key << "floor" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "enabled" << YAML::Value << sf.floor.has_value();
  if (sf.floor) out << YAML::Key << "height" << YAML::Value << *sf.floor;
  out << YAML::EndMap;
}

}  // namespace

std::string scene_to_yaml(const Scene& scene) {
  const Problem& p = scene.problem;
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << p.name;
  out << YAML::Key << "robot" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "urdf" << YAML::Value << scene.urdf_path;
  if (!dynamics::is_identity_pose(scene.base)) {
    out << YAML::Key << "base" << YAML::Value << YAML::BeginMap;
    emit_pose(out, scene.base);
    out << YAML::EndMap;
  }
  if (scene.payload) {
    const PayloadSpec& pl = *scene.payload;
    out << YAML::Key << "payload" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "frame" << YAML::Value << pl.frame;
    out << YAML::Key << "mass" << YAML::Value << pl.mass;
    out << YAML::Key << "size" << YAML::Value;
    emit_vector(out, pl.size);
    out << YAML::Key << "offset" << YAML::Value;
    emit_vector(out, pl.offset);
    out << YAML::EndMap;
  }
  if (!scene.srdf_path.empty()) out << YAML::Key << "srdf" << YAML::Value << scene.srdf_path;
  out << YAML::EndMap;
  out << YAML::Key << "horizon" << YAML::Value << p.horizon;
  out << YAML::Key << "steps" << YAML::Value << p.steps;
  out << YAML::Key << "start" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "q" << YAML::Value;
  emit_vector(out, p.start_q);
  out << YAML::Key << "qd" << YAML::Value;
  emit_vector(out, p.start_qd);
  out << YAML::EndMap;
  out << YAML::Key << "goal" << YAML::Value << YAML::BeginMap;
  if (p.goal.kind == Goal::Kind::kJoint) {
    out << YAML::Key << "q" << YAML::Value;
    emit_vector(out, p.goal.q);
  } else {
    out << YAML::Key << "frame" << YAML::Value << p.goal.frame;
    emit_pose(out, p.goal.pose);
    out << YAML::Key << "position_only" << YAML::Value << p.goal.position_only;
  }
  out << YAML::EndMap;
  emit_limits(out, scene);
  emit_obstacles(out, scene);
  emit_self_and_floor(out, scene);
  if (!p.task_constraints.empty()) {
    out << YAML::Key << "task_constraints" << YAML::Value << YAML::BeginSeq;
    for (const TaskConstraint& t : p.task_constraints) {
      out << YAML::BeginMap;
      out << YAML::Key << "frame" << YAML::Value << t.frame;
      out << YAML::Key << "orientation_only" << YAML::Value << t.orientation_only;
      if (t.orientation_only) {
        emit_rotation(out, t.target.linear());
      } else {
        emit_pose(out, t.target);
      }
      out << YAML::Key << "tolerance" << YAML::Value << t.tolerance;
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  const Objectives& o = p.objectives;
  out << YAML::Key << "objectives" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "min_torque" << YAML::Value << o.min_torque;
  out << YAML::Key << "qc" << YAML::Value << o.qc;
  out << YAML::Key << "collision_epsilon" << YAML::Value << o.collision_epsilon;
  out << YAML::Key << "limit_epsilon" << YAML::Value << o.limit_epsilon;
  out << YAML::Key << "collision_substeps" << YAML::Value << o.collision_substeps;
  out << YAML::Key << "self_collision_epsilon" << YAML::Value << o.self_collision_epsilon;
  out << YAML::Key << "limit_substeps" << YAML::Value << o.limit_substeps;
  out << YAML::EndMap;
  out << YAML::Key << "planner" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "formulation" << YAML::Value << scene.planner.formulation;
  out << YAML::Key << "init" << YAML::Value << scene.planner.init;
  if (!scene.planner.warm.empty()) out << YAML::Key << "warm" << YAML::Value << scene.planner.warm;
  out << YAML::EndMap;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace kinograph::planning

#include "kinograph/planning/io/replan_change.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "kinograph/planning/io/yaml_reader.h"

namespace kinograph::planning {
namespace {

using yaml::line_of;

int index_of(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

}  // namespace

struct ChangeReader::SceneTree {
  YAML::Node root;
};

ChangeReader::ChangeReader(const Scene& scene)
    : scene_(scene),
      tree_(std::make_unique<const SceneTree>(SceneTree{YAML::Load(scene_to_yaml(scene))})) {}

ChangeReader::~ChangeReader() = default;

SceneChange parse_change(const std::string& yaml, const Scene& scene, const std::string& source) {
  return ChangeReader(scene).parse(yaml, source);
}

SceneChange ChangeReader::parse(const std::string& yaml, const std::string& source) const {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw SceneError(source, "", e.mark.line >= 0 ? e.mark.line + 1 : 0, e.msg);
  }
  if (!root.IsMap()) throw SceneError(source, "", 0, "a change file must be a YAML map");
  const yaml::Reader reader(source);
  reader.expect_map(root, "", {"goal", "start", "horizon", "obstacles", "remove"});

  // The scene with the change's entries in place, parsed by the scene parser (one schema); a
  // copy, as assigning into a yaml-cpp tree changes the nodes it shares.
  YAML::Node merged = YAML::Clone(tree_->root);
  for (const char* key : {"goal", "start", "horizon"}) {
    if (root[key]) merged[key] = root[key];
  }
  SceneChange out;
  std::vector<std::string> names = scene_.obstacle_names;
  std::vector<std::string> changed;
  if (root["obstacles"]) {
    const YAML::Node list = root["obstacles"];
    if (!list.IsSequence()) {
      throw SceneError(source, "obstacles", line_of(list), "must be a list of obstacles");
    }
    YAML::Node obstacles =
        merged["obstacles"] ? merged["obstacles"] : YAML::Node(YAML::NodeType::Sequence);
    for (size_t i = 0; i < list.size(); ++i) {
      const std::string key = "obstacles[" + std::to_string(i) + "]";
      if (!list[i].IsMap() || !list[i]["id"]) {
        throw SceneError(source, key, line_of(list[i]), "an obstacle needs an id");
      }
      const std::string name = reader.string(list[i]["id"], key + ".id");
      if (std::find(changed.begin(), changed.end(), name) != changed.end()) {
        throw SceneError(source, key + ".id", line_of(list[i]["id"]),
                         "obstacle '" + name + "' appears twice");
      }
      changed.push_back(name);
      const int idx = index_of(names, name);
      if (idx >= 0) {
        obstacles[idx] = list[i];
      } else {
        obstacles.push_back(list[i]);
        names.push_back(name);
        out.added_names.push_back(name);
      }
    }
    merged["obstacles"] = obstacles;
  }
  if (root["remove"]) {
    const YAML::Node list = root["remove"];
    if (!list.IsSequence()) {
      throw SceneError(source, "remove", line_of(list), "must be a list of obstacle ids");
    }
    for (size_t i = 0; i < list.size(); ++i) {
      const std::string key = "remove[" + std::to_string(i) + "]";
      const std::string name = reader.string(list[i], key);
      const int idx = index_of(scene_.obstacle_names, name);
      if (idx < 0) {
        throw SceneError(source, key, line_of(list[i]),
                         "the scene has no obstacle '" + name + "' to remove");
      }
      if (std::find(changed.begin(), changed.end(), name) != changed.end()) {
        throw SceneError(source, key, line_of(list[i]),
                         "obstacle '" + name + "' is both moved and removed");
      }
      out.change.remove.push_back(idx);
    }
  }
  YAML::Emitter emitter;
  emitter << merged;
  const Scene next = parse_scene(emitter.c_str(), source);

  if (root["goal"]) out.change.goal = next.problem.goal;
  if (root["start"]) {
    out.change.start_q = next.problem.start_q;
    out.change.start_qd = next.problem.start_qd.size() == next.problem.start_q.size()
                              ? next.problem.start_qd
                              : Eigen::VectorXd::Zero(next.problem.start_q.size());
  }
  if (root["horizon"]) out.change.horizon = next.problem.horizon;
  for (const std::string& name : changed) {
    const int idx = index_of(next.obstacle_names, name);
    if (idx < 0) {  // the merged scene's writer changed the name: never index with it
      throw SceneError(source, "obstacles", 0, "obstacle '" + name + "' cannot be read back");
    }
    out.change.add_or_move.push_back(next.problem.obstacles[idx]);
  }
  return out;
}

SceneChange load_change(const std::string& path, const Scene& scene) {
  std::ifstream in(path);
  if (!in) throw SceneError(path, "", 0, "cannot open the change file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_change(ss.str(), scene, path);
}

Scene apply_change(const Scene& scene, const SceneChange& sc) {
  Scene out = scene;
  Problem& p = out.problem;
  const ProblemChange& c = sc.change;
  if (c.goal) p.goal = *c.goal;
  if (c.start_q) p.start_q = *c.start_q;
  if (c.start_qd) p.start_qd = *c.start_qd;
  if (c.horizon) p.horizon = *c.horizon;
  const int scene_count = static_cast<int>(scene.obstacle_names.size());
  for (const collision::Obstacle& o : c.add_or_move) {
    if (o.id < scene_count) {
      p.obstacles[o.id] = o;
    } else {
      p.obstacles.push_back(o);
      out.obstacle_names.push_back(sc.added_names[o.id - scene_count]);
    }
  }
  std::vector<int> removed = c.remove;
  std::sort(removed.rbegin(), removed.rend());
  for (int id : removed) {
    p.obstacles.erase(p.obstacles.begin() + id);
    out.obstacle_names.erase(out.obstacle_names.begin() + id);
  }
  return out;
}

}  // namespace kinograph::planning

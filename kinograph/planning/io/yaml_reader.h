#pragma once
// Typed reading of YAML nodes for kinograph's files (scenes, cells): every error names the
// file, the dotted key path and the line, as a SceneError.
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <functional>
#include <initializer_list>
#include <optional>
#include <string>

#include "kinograph/planning/io/scene.h"

namespace kinograph::planning::yaml {

/// Maps a key path as the reader names it to the path the user wrote (a cell's robot entry is
/// read as a scene: "goal.q" is "robots[1].goal.q" in the file). Identity when empty.
using KeyPathMap = std::function<std::string(const std::string&)>;

/// 1-based line of a node, 0 when yaml-cpp has no mark for it.
int line_of(const YAML::Node& node);
/// "parent.key", or "key" when parent is empty.
std::string join(const std::string& parent, const std::string& key);
/// "parent[i]".
std::string index_key(const std::string& parent, std::size_t i);

/// Reads typed values out of YAML nodes, naming the file, key path and line on every error.
class Reader {
 public:
  explicit Reader(std::string file, KeyPathMap key_path = {});

  /// Throws SceneError for `node` under `key` (mapped by the key path map).
  [[noreturn]] void fail(const YAML::Node& node, const std::string& key,
                         const std::string& message) const;
  /// Requires a map whose keys are all in `allowed`.
  void expect_map(const YAML::Node& node, const std::string& key,
                  std::initializer_list<const char*> allowed) const;
  /// The child `name` of map `parent`; fails naming the key if it is missing.
  YAML::Node required(const YAML::Node& parent, const std::string& parent_key,
                      const std::string& name) const;
  /// A number (angles may use pi), not NaN.
  double number(const YAML::Node& node, const std::string& key) const;
  double positive(const YAML::Node& node, const std::string& key) const;
  double non_negative(const YAML::Node& node, const std::string& key) const;
  double finite(const YAML::Node& node, const std::string& key) const;
  int integer(const YAML::Node& node, const std::string& key) const;
  bool boolean(const YAML::Node& node, const std::string& key) const;
  /// A non-empty string.
  std::string string(const YAML::Node& node, const std::string& key) const;
  /// A list of finite numbers; `size` < 0 accepts any length.
  Eigen::VectorXd vector(const YAML::Node& node, const std::string& key, int size) const;
  Eigen::Vector3d vector3(const YAML::Node& node, const std::string& key) const;
  /// Rotation from `rpy` (URDF fixed-axis roll, pitch, yaw: R = Rz Ry Rx) or `quaternion`
  /// [w, x, y, z]; nullopt when neither is given; both at once is an error.
  std::optional<Eigen::Matrix3d> rotation(const YAML::Node& map, const std::string& key) const;

  const std::string& file() const { return file_; }

 private:
  std::string file_;
  KeyPathMap key_path_;
};

/// Parses a scene from a YAML tree (e.g. put together from a cell file's nodes, whose marks give
/// the lines); `source` names the file and anchors relative paths, `key_path` maps the key
/// paths named in errors. @throws SceneError as parse_scene.
Scene parse_scene_tree(const YAML::Node& root, const std::string& source, KeyPathMap key_path = {});

}  // namespace kinograph::planning::yaml

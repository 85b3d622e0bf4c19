#include "kinograph/planning/io/yaml_reader.h"

#include <cmath>
#include <set>

#include "kinograph/dynamics/utf8.h"
#include "kinograph/planning/io/number_text.h"

namespace kinograph::planning::yaml {

int line_of(const YAML::Node& node) {
  if (!node.IsDefined()) return 0;
  const YAML::Mark mark = node.Mark();
  return mark.is_null() ? 0 : mark.line + 1;
}

std::string join(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

std::string index_key(const std::string& parent, std::size_t i) {
  return parent + "[" + std::to_string(i) + "]";
}

Reader::Reader(std::string file, KeyPathMap key_path)
    : file_(std::move(file)), key_path_(std::move(key_path)) {}

void Reader::fail(const YAML::Node& node, const std::string& key,
                  const std::string& message) const {
  throw SceneError(file_, key_path_ ? key_path_(key) : key, line_of(node), message);
}

void Reader::expect_map(const YAML::Node& node, const std::string& key,
                        std::initializer_list<const char*> allowed) const {
  if (!node.IsMap()) fail(node, key, "must be a map");
  std::set<std::string> seen;
  for (const auto& entry : node) {
    if (!entry.first.IsScalar()) fail(entry.first, key, "has a key that is not a string");
    const std::string name = entry.first.Scalar();
    if (!seen.insert(name).second) fail(entry.first, join(key, name), "duplicate key");
    bool known = false;
    for (const char* a : allowed) known = known || name == a;
    if (!known) {
      std::string list;
      for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
      fail(entry.first, join(key, name), "unknown key (expected one of: " + list + ")");
    }
  }
}

YAML::Node Reader::required(const YAML::Node& parent, const std::string& parent_key,
                            const std::string& name) const {
  const YAML::Node child = parent[name];
  if (!child) fail(parent, join(parent_key, name), "missing required key");
  return child;
}

double Reader::number(const YAML::Node& node, const std::string& key) const {
  if (!node.IsScalar()) fail(node, key, "must be a number");
  const std::string text = node.Scalar();
  const std::optional<double> value = parse_number_text(text);  // angles may use pi
  if (!value) fail(node, key, "must be a number, got '" + text + "'");
  if (std::isnan(*value)) fail(node, key, "must not be NaN");
  return *value;
}

double Reader::positive(const YAML::Node& node, const std::string& key) const {
  const double v = number(node, key);
  if (!(v > 0) || !std::isfinite(v)) fail(node, key, "must be a positive finite number");
  return v;
}

double Reader::non_negative(const YAML::Node& node, const std::string& key) const {
  const double v = number(node, key);
  if (!(v >= 0) || !std::isfinite(v)) fail(node, key, "must be a finite number >= 0");
  return v;
}

double Reader::finite(const YAML::Node& node, const std::string& key) const {
  const double v = number(node, key);
  if (!std::isfinite(v)) fail(node, key, "must be finite");
  return v;
}

int Reader::integer(const YAML::Node& node, const std::string& key) const {
  int value = 0;
  if (!node.IsScalar() || !YAML::convert<int>::decode(node, value)) {
    fail(node, key, "must be an integer");
  }
  return value;
}

bool Reader::boolean(const YAML::Node& node, const std::string& key) const {
  bool value = false;
  if (!node.IsScalar() || !YAML::convert<bool>::decode(node, value)) {
    fail(node, key, "must be true or false");
  }
  return value;
}

std::string Reader::string(const YAML::Node& node, const std::string& key) const {
  if (!node.IsScalar() || node.Scalar().empty()) fail(node, key, "must be a non-empty string");
  // YAML text is UTF-8; other bytes would not survive a scene written back (plan files, changes).
  if (dynamics::first_invalid_utf8(node.Scalar())) fail(node, key, "is not UTF-8 text");
  return node.Scalar();
}

Eigen::VectorXd Reader::vector(const YAML::Node& node, const std::string& key, int size) const {
  if (!node.IsSequence()) fail(node, key, "must be a list of numbers");
  if (size >= 0 && static_cast<int>(node.size()) != size) {
    fail(node, key,
         "must have " + std::to_string(size) + " numbers, has " + std::to_string(node.size()));
  }
  Eigen::VectorXd v(node.size());
  for (std::size_t i = 0; i < node.size(); ++i) v[i] = finite(node[i], index_key(key, i));
  return v;
}

Eigen::Vector3d Reader::vector3(const YAML::Node& node, const std::string& key) const {
  return vector(node, key, 3);
}

std::optional<Eigen::Matrix3d> Reader::rotation(const YAML::Node& map,
                                                const std::string& key) const {
  const YAML::Node rpy = map["rpy"], quat = map["quaternion"];
  if (rpy && quat) fail(quat, join(key, "quaternion"), "give either rpy or quaternion, not both");
  if (rpy) {
    const Eigen::Vector3d a = vector3(rpy, join(key, "rpy"));
    return (Eigen::AngleAxisd(a.z(), Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(a.y(), Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(a.x(), Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
  }
  if (quat) {
    const Eigen::VectorXd q = vector(quat, join(key, "quaternion"), 4);
    Eigen::Quaterniond r(q[0], q[1], q[2], q[3]);
    if (r.norm() < 1e-9) fail(quat, join(key, "quaternion"), "must not be zero");
    return r.normalized().toRotationMatrix();
  }
  return std::nullopt;
}

}  // namespace kinograph::planning::yaml

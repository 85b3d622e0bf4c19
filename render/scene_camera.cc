#include "render/scene_camera.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <stdexcept>

namespace kinograph::render {

namespace {

Eigen::Vector3d vector3(const YAML::Node& node, const std::string& path, const char* key) {
  if (!node.IsSequence() || node.size() != 3) {
    throw std::runtime_error(fmt::format("scene '{}': 'camera.{}' must be [x, y, z]", path, key));
  }
  return Eigen::Vector3d(node[0].as<double>(), node[1].as<double>(), node[2].as<double>());
}

}  // namespace

std::optional<Camera> read_scene_camera(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(fmt::format("cannot read scene '{}': {}", path, e.what()));
  }
  const YAML::Node node = root["camera"];
  if (!node) return std::nullopt;
  try {
    Camera camera;
    if (!node["eye"] || !node["target"]) {
      throw std::runtime_error(fmt::format("scene '{}': 'camera' needs 'eye' and 'target'", path));
    }
    camera.eye = vector3(node["eye"], path, "eye");
    camera.target = vector3(node["target"], path, "target");
    if (node["up"]) camera.up = vector3(node["up"], path, "up");
    if (node["fov_y_deg"]) camera.fov_y_deg = node["fov_y_deg"].as<double>();
    const double distance = (camera.eye - camera.target).norm();
    if (distance <= 0)
      throw std::runtime_error(fmt::format("scene '{}': camera.eye == target", path));
    camera.near = 0.02 * distance;
    camera.far = 20.0 * distance + 10.0;
    return camera;
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(fmt::format("scene '{}': bad 'camera' block: {}", path, e.what()));
  }
}

}  // namespace kinograph::render

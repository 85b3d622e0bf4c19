#pragma once
// The camera block of a scene file, so a scene can fix the view of its pictures.
#include <optional>
#include <string>

#include "render/camera.h"

namespace kinograph::render {

/// Reads the optional `camera:` block of a scene YAML file:
///   camera: {eye: [x, y, z], target: [x, y, z], up: [0, 0, 1], fov_y_deg: 30}
/// (up and fov_y_deg optional). Returns nullopt when the file has no camera block; throws
/// std::runtime_error naming the file and key when it cannot be read or is malformed.
std::optional<Camera> read_scene_camera(const std::string& path);

}  // namespace kinograph::render

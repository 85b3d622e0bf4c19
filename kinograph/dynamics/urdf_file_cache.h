#pragma once
// A scope in which Model::from_urdf_file reads each URDF file once.
#include <exception>
#include <map>
#include <mutex>
#include <string>
#include <variant>

#include "kinograph/dynamics/model.h"

namespace kinograph::dynamics {

/// While one is alive, Model::from_urdf_file loads each path once and returns copies (or
/// rethrows the first load's error): for a process that reads many inputs naming the same
/// robot, e.g. the scene and plan fuzz targets. The files must not change meanwhile.
class UrdfFileCache {
 public:
  UrdfFileCache();
  ~UrdfFileCache();
  UrdfFileCache(const UrdfFileCache&) = delete;
  UrdfFileCache& operator=(const UrdfFileCache&) = delete;

  /// How many files were read (each path once, failed ones included).
  int loads() const;

  /// The cache in scope, nullptr when none.
  static UrdfFileCache* active();
  /// The model of `path`, read with `load` the first time.
  Model get(const std::string& path, Model (*load)(const std::string&));

 private:
  mutable std::mutex mutex_;
  std::map<std::string, std::variant<Model, std::exception_ptr>> entries_;
};

}  // namespace kinograph::dynamics

#pragma once
// Where the fuzz targets find the shipped robots and scenes, and the robots they load once.
#include <cstdlib>
#include <string>

#include "kinograph/dynamics/model.h"
#include "kinograph/dynamics/urdf_file_cache.h"

namespace kinograph::fuzz {

/// A path under the source tree (KINOGRAPH_SOURCE_DIR), e.g. "robots/rr/rr.urdf".
inline std::string source_path(const std::string& relative) {
  return std::string(KINOGRAPH_SOURCE_DIR) + "/" + relative;
}

/// Makes the source tree the data directory (data_dir.h) of this process, so files that name
/// "robots/rr/rr.urdf" find it wherever they are; an explicit KINOGRAPH_DATA_DIR wins.
inline void use_source_data_dir() { setenv("KINOGRAPH_DATA_DIR", KINOGRAPH_SOURCE_DIR, 0); }

/// The iiwa14 model, read once: the robot the message conversions are checked against.
inline const dynamics::Model& iiwa_model() {
  static const dynamics::Model model =
      dynamics::Model::from_urdf_file(source_path("robots/iiwa14/iiwa14.urdf"));
  return model;
}

/// Makes Model::from_urdf_file read each robot once for the rest of the process: the scene,
/// change and plan readers load the robot a file names for every input, and that load (fuzzed
/// by urdf_model) took most of each input's time.
inline void read_each_urdf_once() { static const dynamics::UrdfFileCache cache; }

/// Stops the run (a finding for libFuzzer, a failure for the corpus replay) with `what`.
[[noreturn]] void fail(const std::string& what);

/// Whether `message` names `source`: every error of a file reader must say which file it is.
void expect_names(const std::string& message, const std::string& source);

}  // namespace kinograph::fuzz

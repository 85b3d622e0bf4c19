#pragma once
// Where the shipped robots and scenes are found at run time: never through a path compiled
// into the library, so a build tree, an installed prefix and a moved install all work.
#include <filesystem>
#include <string>
#include <vector>

namespace kinograph::planning {

/// The environment variable that names a data directory (one holding robots/), tried first.
inline constexpr const char* kDataDirVariable = "KINOGRAPH_DATA_DIR";

/// The data directories, in the order they are searched, that exist: $KINOGRAPH_DATA_DIR,
/// then `<directory of the running program>/../share/kinograph` (an installed prefix, or the
/// build tree's share/kinograph).
std::vector<std::filesystem::path> data_dirs();

/// Where data_dirs() looked, for error messages, e.g. "KINOGRAPH_DATA_DIR (not set) and
/// /opt/kg/share/kinograph".
std::string describe_data_dirs();

/// `path` relative to the data directory that holds it ("robots/rr/rr.urdf"), so that plan
/// files stay valid when the data moves; the absolute path when no data directory holds it.
std::string data_relative_path(const std::string& path);

}  // namespace kinograph::planning

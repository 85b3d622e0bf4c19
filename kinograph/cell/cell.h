#pragma once
// Cell files (YAML): several robots sharing one workspace — shared obstacles, floor, horizon,
// steps and objectives, and per robot its name, URDF, base pose, start and goal, all in the
// scene file's conventions (robots/cells/README.md). A cell gives one single-robot Scene per
// robot (what each robot's own daemon plans) and the centralized problem (composite_problem.h).
#include <string>
#include <vector>

#include "kinograph/planning/io/scene.h"

namespace kinograph::cell {

/// One robot of a cell: its name and its own scene (the cell's shared keys with its robot,
/// start, goal and its other per-robot keys). The other robots are not in it.
struct CellRobot {
  std::string name;
  planning::Scene scene;
};

/// A parsed cell file.
struct Cell {
  std::string source;  ///< file it was read from; empty when parsed from text
  std::string name;    ///< "name", else the file's stem
  std::vector<CellRobot> robots;
  /// Index of the robot with this name; throws std::out_of_range naming it.
  int robot_index(const std::string& name) const;
};

/// Reads a cell file; relative paths resolve against its directory, then the data directories.
/// @throws planning::SceneError naming the file, the key path (e.g. "robots[1].goal.q") and the
///   line: unknown or missing keys, a robot name that is empty, repeated or holds '/', fewer
///   than one robot, and everything a scene file may get wrong.
Cell load_cell(const std::string& path);

/// Parses cell text; `source` names it in errors and anchors relative paths.
/// @throws planning::SceneError as load_cell.
Cell parse_cell(const std::string& yaml, const std::string& source = "");

}  // namespace kinograph::cell

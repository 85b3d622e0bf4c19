#pragma once
// Change files (YAML) for replanning: what changed since a scene was planned — a new goal, a
// measured start state, a new horizon, obstacles added or moved, obstacles removed. Entries use
// the scene file's schema (robots/scenes/README.md), so a change reads like a scene fragment:
//
//   goal: {q: [...]}                  # or a pose goal, as in a scene
//   start: {q: [...], qd: [...]}      # the measured robot state
//   horizon: 2.5                      # s (same number of steps)
//   obstacles:                        # by id: a scene obstacle's id moves/replaces it,
//     - {id: ball, shape: sphere, size: [0.15], position: [0.3, 0, 1.5]}   # a new id adds one
//   remove: [desk_leg_1]              # ids of scene obstacles to remove
//
// Examples live in robots/scenes/changes/.
#include <memory>
#include <string>
#include <vector>

#include "kinograph/planning/incremental/incremental_planner.h"
#include "kinograph/planning/io/scene.h"

namespace kinograph::planning {

/// A parsed change file: the change in the scene's obstacle ids (scene obstacle i has id i; new
/// obstacles get ids after the scene's), and the names of the obstacles it adds.
struct SceneChange {
  ProblemChange change;
  /// Names of obstacles the change adds (id = scene obstacle count + position in this list).
  std::vector<std::string> added_names;
};

/// Parses change text for `scene`; `source` names it in errors and anchors relative paths.
/// Throws SceneError naming the file and key (unknown keys, bad values, unknown ids to remove).
SceneChange parse_change(const std::string& yaml, const Scene& scene,
                         const std::string& source = "");
/// Parses change texts for one scene, which it writes out as YAML once for all of them (the
/// change's entries are merged into that tree). `scene` must outlive the reader.
class ChangeReader {
 public:
  explicit ChangeReader(const Scene& scene);
  ~ChangeReader();
  /// As parse_change(yaml, scene, source).
  /// @throws SceneError naming `source`, the key and the line of what is wrong.
  SceneChange parse(const std::string& yaml, const std::string& source = "") const;

 private:
  struct SceneTree;
  const Scene& scene_;
  std::unique_ptr<const SceneTree> tree_;
};

/// Reads a change file for `scene`. Throws SceneError.
SceneChange load_change(const std::string& path, const Scene& scene);

/// The scene after the change (for plan files): obstacles moved, added and removed, goal, start
/// and horizon replaced.
Scene apply_change(const Scene& scene, const SceneChange& change);

}  // namespace kinograph::planning

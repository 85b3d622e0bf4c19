#pragma once
// What kinographd remembers across a restart (--state-file): the plan ids it may have used,
// so that a restarted daemon never reuses one, and the obstacles it received over LCM. The
// current goal and plan are not kept: a restarted daemon must not resume a motion on its own.
// The file is JSON, written whole to a temporary file and renamed over the old one, so a crash
// leaves the old file or the new one, never a part (docs/reliability.md, "Restarts").
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>

#include "kinograph/collision/shape.h"
#include "kinograph/lcm/message_convert.h"

namespace kinograph::daemon {

/// A state file that cannot be read, is not a kinographd state file, or belongs to another
/// daemon; the message names the file (and the line or key).
class StateFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The remembered state of one daemon.
struct DaemonState {
  std::string robot;   ///< URDF robot name of the daemon that wrote it
  std::string prefix;  ///< its channel prefix
  /// Every plan id the daemon used or may have used is below this one.
  int64_t plan_ids_below = 1;
  /// Obstacles received over LCM, by their source and id (shape and pose).
  std::map<messages::ObstacleKey, messages::ObstacleUpdate> obstacles;
};

/// Reads the state file at `path`, checking it was written for `robot` on `prefix` and that
/// every obstacle is within the collision engine's faithful range (collision/shape.h).
/// @throws StateFileError naming the file: unreadable, not JSON (with its line), not a
///         kinographd state file of a known version, another robot's or prefix's, a bad field.
DaemonState read_state_file(const std::string& path, const std::string& robot,
                            const std::string& prefix);

/// Writes `state` to `path` atomically (to path + ".tmp", flushed, then renamed over path).
/// @throws StateFileError naming the file when it cannot be written.
void write_state_file(const std::string& path, const DaemonState& state);

}  // namespace kinograph::daemon

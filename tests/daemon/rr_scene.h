#pragma once
// The RR arm scene the daemon's end-to-end tests plan in: 2 s from one side to the other.
#include <string>

#include "kinograph/planning/io/scene.h"

namespace kinograph::daemon::testing {

inline planning::Scene rr_daemon_scene() {
  constexpr char kScene[] = R"(
name: rr_daemon_test
robot:
  urdf: robots/rr/rr.urdf
horizon: 2.0
steps: 30
start:
  q: [-0.8, 0.4]
goal:
  q: [0.8, -0.4]
)";
  return planning::parse_scene(kScene, std::string(KINOGRAPH_SOURCE_DIR) + "/scene.yaml");
}

}  // namespace kinograph::daemon::testing

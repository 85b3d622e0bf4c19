#include "daemon/robot_payload.h"

namespace kinograph::daemon {

RobotWithPayload robot_with_payload(const planning::Scene& scene,
                                    const std::optional<planning::PayloadSpec>& payload) {
  planning::Scene changed = scene;
  changed.payload = payload;
  // Written back and read again: the reader attaches the box, then applies the limit overrides
  // and the allowed collisions, as it does for a scene file.
  planning::Scene parsed = planning::parse_scene(planning::scene_to_yaml(changed), scene.source);
  return {parsed.problem.model, parsed.problem.self_and_floor};
}

}  // namespace kinograph::daemon

#pragma once
// The robot a daemon plans for after a payload_t: its scene's robot with another payload (or
// none), built by the scene reader itself so that it is exactly what a scene file with that
// robot.payload would give.
#include <memory>
#include <optional>

#include "kinograph/planning/io/scene.h"

namespace kinograph::daemon {

/// The robot's model and what it must clear, as the plans after a payload change use them.
struct RobotWithPayload {
  std::shared_ptr<const dynamics::Model> model;
  planning::SelfAndFloor self_and_floor;
};

/// `scene`'s robot carrying `payload` instead of the scene's own (nullopt: no payload). Throws
/// planning::SceneError, naming robot.payload, when the box cannot be attached.
RobotWithPayload robot_with_payload(const planning::Scene& scene,
                                    const std::optional<planning::PayloadSpec>& payload);

}  // namespace kinograph::daemon

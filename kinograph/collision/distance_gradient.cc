#include "kinograph/collision/distance_gradient.h"

#include "kinograph/dynamics/kinematics.h"

namespace kinograph::collision {

void distance_gradient(const dynamics::Model& model, const dynamics::Data& data,
                       const Proximity& proximity, DistanceGradientWorkspace& workspace,
                       Eigen::Ref<Eigen::VectorXd> gradient) {
  const int body = model.collision[proximity.robot_geom].body;
  dynamics::point_jacobian(model, data, body, proximity.point_on_robot, workspace.J_robot);
  gradient.noalias() = workspace.J_robot.transpose() * proximity.normal;
  if (proximity.is_self_collision()) {
    const int other = model.collision[proximity.other_geom].body;
    dynamics::point_jacobian(model, data, other, proximity.point_on_obstacle, workspace.J_other);
    gradient.noalias() -= workspace.J_other.transpose() * proximity.normal;
  }
}

}  // namespace kinograph::collision

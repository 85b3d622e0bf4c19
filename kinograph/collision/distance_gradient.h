#pragma once

#include <Eigen/Core>

#include "kinograph/collision/proximity.h"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/model.h"

namespace kinograph::collision {

// Preallocated point Jacobians for distance_gradient, sized for one Model.
struct DistanceGradientWorkspace {
  explicit DistanceGradientWorkspace(const dynamics::Model& model)
      : J_robot(3, model.nq()), J_other(3, model.nq()) {}
  Eigen::Matrix3Xd J_robot, J_other;
};

// ∂d/∂q (length nq) of a pair's signed distance at the configuration of the last
// forward_kinematics on `data`: nᵀ J_p(point_on_robot), the witness point held fixed on its
// body (exact where the witness is unique). For a self-collision pair the second body moves
// too: nᵀ (J_a(p_a) − J_b(p_b)). A moving obstacle contributes nothing (it does not depend on
// q). Allocates nothing.
void distance_gradient(const dynamics::Model& model, const dynamics::Data& data,
                       const Proximity& proximity, DistanceGradientWorkspace& workspace,
                       Eigen::Ref<Eigen::VectorXd> gradient);

}  // namespace kinograph::collision

#pragma once
// Forward kinematics and Jacobians.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/model.h"

namespace kinograph::dynamics {

/// Fills data.body_pose with the world pose of every body at joint positions q.
void forward_kinematics(const Model& model, Data& data, const Eigen::Ref<const Eigen::VectorXd>& q);

/// World pose of a frame (index into model.frames), after forward_kinematics.
Eigen::Isometry3d frame_pose(const Model& model, const Data& data, int frame);

/// Space Jacobian of a body (MR eq. 5.11): column j is joint j's screw in the world frame when
/// j moves the body, zero otherwise, so the body's world twist is J q̇. J is 6 × nq.
/// After forward_kinematics.
void space_jacobian(const Model& model, const Data& data, int body,
                    Eigen::Ref<Eigen::Matrix<double, 6, Eigen::Dynamic>> J);

/// ∂p/∂q (3 × nq) of a point fixed on `body` (-1 = base: zero) given by its current world
/// position, so its world velocity is J q̇. After forward_kinematics.
void point_jacobian(const Model& model, const Data& data, int body,
                    const Eigen::Vector3d& point_world, Eigen::Ref<Eigen::Matrix3Xd> J);

}  // namespace kinograph::dynamics

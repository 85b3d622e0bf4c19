#pragma once
// A planning problem: everything one plan depends on (robot, horizon, start, goal, obstacles,
// task constraints and the weights of the soft objectives). Scene files describe one.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "kinograph/collision/obstacle.h"
#include "kinograph/dynamics/model.h"

namespace kinograph::planning {

/// Where the trajectory ends; in both kinds the robot ends at rest (q̇_N = q̈_N = 0).
struct Goal {
  enum class Kind { kJoint, kPose };
  Kind kind = Kind::kJoint;
  Eigen::VectorXd q;  ///< kJoint: the final configuration (nq entries)
  std::string frame;  ///< kPose: a frame name of the Model (e.g. "iiwa_link_ee_kuka")
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< kPose: desired world pose
  bool position_only = false;  ///< kPose: ignore the orientation of `pose`
  /// How far from the goal the plan may end and still validate; 0 (or empty) = the validator's
  /// ValidationThresholds::goal. kJoint: per joint, nq entries or empty (rad, or m).
  Eigen::VectorXd joint_tolerance;
  double position_tolerance = 0;     ///< kPose: m
  double orientation_tolerance = 0;  ///< kPose: rad (unused with position_only)
};

/// Keeps a frame's orientation (or full pose) at `target` at every step, e.g. to keep a carried
/// block level. Errors are the rotation angle (rad) and position distance (m).
struct TaskConstraint {
  std::string frame;
  bool orientation_only = true;
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  double tolerance = 0.05;  ///< rad (and m); the validator's threshold for this constraint
};

/// Soft terms and planner margins, with their defaults.
struct Objectives {
  /// Weight w of the minimum-torque term w·Σ_k Σ_j τ_kj² (0 = off).
  double min_torque = 0.0;
  /// Power-spectral density Qc (per joint) of the GP constant-acceleration (white-noise jerk)
  /// prior; larger means a weaker smoothness prior.
  double qc = 1.0;
  /// Safety distance ε (m) of the collision hinge: the planner keeps every robot body at least
  /// this far from every obstacle (the validator only requires no penetration).
  double collision_epsilon = 0.05;
  /// Margin ε of the limit hinges: the planner keeps q, q̇, q̈, τ this far inside their limits.
  double limit_epsilon = 0.0;
  /// Number of interpolated states checked for collision between consecutive steps by the
  /// planner's collision factors (0 = only at the steps).
  int collision_substeps = 1;
  /// Safety distance (m) the planner keeps between two links of the robot and between a link
  /// and the floor: smaller than ε, since an arm's own links pass close by design (links two
  /// joints apart are 4.5 cm apart on the iiwa) and it works close to the floor it stands on.
  double self_collision_epsilon = 0.01;
  /// Interior limit points per interval (evenly spaced, limit_points in interpolant.h raises
  /// them to one per RK4 node): where the interval factor can enforce the effort, q and q̇
  /// limits on the interpolant; 0 = only at the knots. The batch planner adds them only on
  /// intervals that came near a limit (batch/interval_limits.h), the incremental planner on
  /// every interval. The default matches the validator's 10 samples per interval.
  int limit_substeps = 9;
};

/// What the robot must clear besides the obstacles: its own links and the floor.
struct SelfAndFloor {
  /// Check every pair of links that are neither the same nor parent and child.
  bool self_collision = true;
  /// Body pairs (Model::bodies indices, −1 = the base) allowed to touch, never checked (an
  /// SRDF's disable_collisions, the scene's allowed_collisions).
  std::vector<std::pair<int, int>> allowed_pairs;
  /// World height (m) of a floor (the half-space below it) that every moving link and the
  /// payload must clear; no floor when unset. The base is not checked: it stands on it.
  std::optional<double> floor;
};

/// A kinodynamic planning problem: move from (start_q, start_qd) to the goal in `horizon`
/// seconds over `steps` intervals, within all limits, without collision.
struct Problem {
  std::string name;
  /// The robot (payload attached, limit overrides applied).
  std::shared_ptr<const dynamics::Model> model;
  double horizon = 1.0;  ///< s
  int steps = 50;        ///< intervals; states 0..steps
  Eigen::VectorXd start_q, start_qd;
  Goal goal;
  std::vector<collision::Obstacle> obstacles;
  std::vector<TaskConstraint> task_constraints;
  Objectives objectives;
  SelfAndFloor self_and_floor;

  /// Time between consecutive states (s).
  double dt() const { return horizon / steps; }
};

}  // namespace kinograph::planning

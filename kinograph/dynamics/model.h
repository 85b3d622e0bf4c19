#pragma once
// Model: the immutable description of a robot arm read from URDF — kinematic tree with fixed
// joints merged, screw axes, spatial inertias, limits, damping and geometry.
//
// Frames and signs (Lynch & Park ch. 8, as the paper):
// - One Body per degree of freedom, in topological order (parent index < own index). A body's
//   frame is the URDF child link's frame of its joint: it sits on the joint axis, so the
//   screw axis A of a revolute joint is [axis; 0] and of a prismatic joint [0; axis].
// - Pose of a body in its parent body: T_parent,body(q) = parent_to_joint · exp([A] q).
// - The root link is the fixed base (body index -1) and its frame is the world frame.
// - Gravity is a world-frame vector; dynamics treat it as a base acceleration of −g.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>
#include <string>
#include <vector>

#include "kinograph/dynamics/geometry.h"
#include "kinograph/dynamics/se3.h"
#include "kinograph/dynamics/urdf_error.h"

namespace kinograph::dynamics {

/// One-degree-of-freedom joint kinds; a URDF continuous joint is a revolute joint whose
/// position limits are infinite, and fixed joints are merged away.
enum class JointType { kRevolute, kPrismatic };

/// Joint limits in SI units (rad or m, per second, N·m or N); +inf / -inf where absent.
/// URDF has no acceleration limit: it defaults to +inf and can be set on a copy of the Model.
struct JointLimits {
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  double velocity = std::numeric_limits<double>::infinity();
  double effort = std::numeric_limits<double>::infinity();
  double acceleration = std::numeric_limits<double>::infinity();
};

/// One moving body: the URDF child link of a non-fixed joint plus every link fixed to it.
struct Body {
  std::string name;        ///< URDF child link name
  std::string joint_name;  ///< URDF joint that moves this body
  JointType joint_type = JointType::kRevolute;
  int parent = -1;  ///< parent body index, -1 = the fixed base
  /// This body's frame in the parent body's frame at q = 0 (fixed joints merged into it).
  Eigen::Isometry3d parent_to_joint = Eigen::Isometry3d::Identity();
  Vector6 screw_axis = Vector6::Zero();  ///< A: the joint's unit screw in this body's frame
  /// Spatial inertia G about this body's frame origin, in its frame, so that the body's
  /// wrench is G V̇ − [ad_V]^T G V (MR eq. 8.42); merged fixed children are included.
  Matrix6 inertia = Matrix6::Zero();
  JointLimits limits;
  double damping = 0.0;  ///< viscous joint damping b: τ gets + b q̇
  /// false for a passive joint (e.g. the Acrobot shoulder): URDF cannot say so, a scene's
  /// `unactuated` list does. The loader reads effort="0" as an unknown limit (+inf), with a warning.
  bool actuated = true;
};

/// A named frame: every URDF link (including the root and merged links), fixed on a body.
struct Frame {
  std::string name;
  int body = -1;  ///< owning body index, -1 = the fixed base
  Eigen::Isometry3d placement = Eigen::Isometry3d::Identity();  ///< pose in the body's frame
};

/// The immutable robot description; algorithms take it with a Data workspace.
class Model {
 public:
  /// Reads a URDF file; every joint actuated (effort="0" is logged as unknown and read as +inf).
  /// @throws UrdfError naming the file, the link or joint, the element and its line: unreadable
  ///   file, malformed XML, a xacro file (to be expanded first), an attribute that is not a
  ///   number, geometry urdfdom could not read, an unsupported joint, a moving link without
  ///   inertial, a mesh not found.
  static Model from_urdf_file(const std::string& path);
  /// Parses URDF text; relative mesh paths resolve against base_dir (the working directory
  /// when empty). @throws UrdfError as from_urdf_file.
  static Model from_urdf_string(const std::string& xml, const std::string& base_dir = "");

  /// Number of joint coordinates (= number of bodies).
  int nq() const { return static_cast<int>(bodies.size()); }
  /// Index into frames of the frame with this name; throws std::out_of_range naming it.
  int frame_index(const std::string& name) const;
  /// Index into bodies of the body whose URDF link is `link`; throws std::out_of_range.
  int body_index(const std::string& link) const;
  /// Total mass of the moving bodies (the fixed base is not included).
  double total_mass() const;

  std::string name;       ///< URDF robot name
  std::string urdf_path;  ///< file read, empty when built from a string
  std::vector<Body> bodies;
  std::vector<Frame> frames;
  std::vector<Geometry> collision, visual;
  Eigen::Vector3d gravity{0, 0, -9.81};  ///< world-frame gravitational acceleration
  double base_mass = 0.0;                ///< mass of the links fixed to the base (not in any body)
};

}  // namespace kinograph::dynamics

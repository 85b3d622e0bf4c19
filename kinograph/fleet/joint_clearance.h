#pragma once
// Several robots' plans checked together on a common clock: each robot's collision bodies
// against every other robot's at the same times, at and between the knots.
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "kinograph/dynamics/model.h"
#include "kinograph/planning/plan.h"

namespace kinograph::fleet {

/// One robot of a joint check: its model placed at its base (payload attached), its plan, and
/// where the plan's time 0 lies on the common clock.
struct RobotPlan {
  std::string name;
  std::shared_ptr<const dynamics::Model> model;
  planning::Plan plan;
  double offset = 0;  ///< s: plan time τ is common time offset + τ
};

/// How densely joint_clearance samples the motion.
struct JointClearanceOptions {
  /// Points per interval of every robot's plan (its knot and samples_per_interval − 1 evenly
  /// between); all robots are posed at the union of these times. Default 10, as the validator.
  int samples_per_interval = 10;
  /// Common-clock time (s) from which on the robots are checked: what lies before (a neighbour's
  /// motion already past) is left out. Default −∞: the whole span.
  double from = -std::numeric_limits<double>::infinity();
  /// Common-clock time (s) before which the check ends (not included): what lies after is left
  /// out. Default +∞.
  double to = std::numeric_limits<double>::infinity();
};

/// The closest approach of two different robots over the common span of their plans (each one
/// at its first knot before its plan starts and at its last after it ends).
struct JointClearance {
  /// Smallest signed distance (m) between bodies of two different robots; negative inside,
  /// +inf when no two robots have collision geometry.
  double min_distance = std::numeric_limits<double>::infinity();
  double t = 0;                 ///< common-clock time (s) of the closest approach
  std::string robot_a, link_a;  ///< one robot of the closest pair and its link
  std::string robot_b, link_b;  ///< the other
  int samples = 0;              ///< common times checked

  /// True when the robots keep at least `required` metres apart.
  bool clear(double required = 0.0) const { return min_distance >= required; }
};

/// One robot's motion made of the plans it was given, in the order given: each plan is in force
/// from its start (common time `offset`) until a later one of the list starts; before any has
/// started the robot stands at the first plan's first knot. A robot without measured states that
/// follows its daemon's plans moves so.
struct RobotHistory {
  std::string name;
  std::shared_ptr<const dynamics::Model> model;
  struct Piece {
    planning::Plan plan;
    double offset = 0;  ///< s: plan time τ is common time offset + τ
  };
  std::vector<Piece> plans;  ///< at least one
};

/// Window checks already made by history_clearance, to be reused by a later call whose histories
/// only have plans appended.
using HistoryMemo = std::map<std::string, JointClearance>;

/// The closest approach between every pair of robots moving as their histories say: the common
/// clock cut where any robot's plan in force changes, and each window checked as joint_clearance
/// does with the plans in force there (options.from / to bound the whole). With `memo`, windows
/// checked before with the same plans in force are not checked again. Throws as joint_clearance,
/// and std::invalid_argument for a history without plans.
JointClearance history_clearance(const std::vector<RobotHistory>& robots,
                                 const JointClearanceOptions& options = {},
                                 HistoryMemo* memo = nullptr);

/// A plan standing still at configuration q from time 0 to `duration` s (two knots, at rest): a
/// robot held at a state, for joint_clearance.
planning::Plan standing_plan(const Eigen::VectorXd& q, double duration = 1.0);

/// One line: "robots 'a' (link 'l') and 'b' (link 'm') are 0.12 m apart at t = 1.4 s" (or
/// "overlap by ...").
std::string describe(const JointClearance& clearance);

/// The closest approach between every pair of the robots. Throws std::invalid_argument naming
/// the robot whose plan does not fit its model, two robots of the same name, or options < 1.
JointClearance joint_clearance(const std::vector<RobotPlan>& robots,
                               const JointClearanceOptions& options = {});

}  // namespace kinograph::fleet

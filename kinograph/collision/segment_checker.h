#pragma once

#include <Eigen/Core>
#include <limits>
#include <vector>

#include "kinograph/collision/collision_world.h"
#include "kinograph/collision/proximity.h"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/model.h"

namespace kinograph::collision {

// Sample spacing for checking the straight joint-space segment between two configurations
// (between the planner's time steps, and in plan validation), so thin obstacles are not
// jumped over.
struct SegmentCheckOptions {
  // Largest change of any one joint between samples (rad or m). Default 0.05.
  double max_joint_step = 0.05;
  // Largest distance any point of the robot's collision geometry can move between samples
  // (m), from a configuration-independent bound of each joint's lever arm. Default 0.01.
  // Against fixed obstacles the true minimum along the segment is then at least the sampled
  // minimum minus half of this, so no obstacle thicker than it is jumped over.
  double max_sweep_step = 0.01;
  // Largest time between samples (s) when the world has moving obstacles, whose own motion
  // the sweep bound does not cover. Default 0.02.
  double max_time_step = 0.02;
  // Most configurations check_path queries. A path that sweeps kilometres (a plan file with
  // q = 1e308) would otherwise take forever; the walk stops there and says so. Default 200,000.
  int max_path_samples = 200000;
  // Most distance (m) check_path lets a point of the robot sweep along a path: no arm's plan
  // moves its geometry a kilometre, and a plan file that does (q̇ = 1e7) would spend the whole
  // query budget on it. The walk stops there and says so. Default 1,000 m.
  double max_path_sweep = 1000;
  // check_path stops at the first sample whose distance falls below this (m): a caller that
  // asks only whether a path keeps a clearance has its answer there. Default −∞: never.
  double stop_below = -std::numeric_limits<double>::infinity();
};

// The smallest signed distance found along a segment.
struct SegmentCheckResult {
  // Smallest signed distance over all samples (+inf when the world has nothing to check).
  double min_distance = 0;
  // Fraction in [0, 1] of the way from q0 to q1 where it occurs.
  double s = 0;
  // The closest pair at that sample.
  Proximity closest;
  // Number of configurations checked, both ends included.
  int samples = 0;
};

// The smallest signed distance found along a path (a polyline of configurations).
struct PathCheckResult {
  // Smallest signed distance over the configurations checked (+inf when nothing to check).
  double min_distance = 0;
  // A lower bound of the true distance along the whole polyline against fixed obstacles: each
  // stretch between two samples a, b that sweeps at most L (m) stays at least (d_a + d_b − L) / 2
  // away. Not a bound when obstacles move.
  double lower_bound = 0;
  // Where min_distance occurs: polyline segment index and fraction along it.
  int segment = 0;
  double s = 0;
  // The closest pair there.
  Proximity closest;
  // Number of configurations checked.
  int samples = 0;
  // Distance (m) the walk let a point of the robot sweep, up to where it stopped.
  double swept = 0;
  // False when the walk stopped at max_path_samples or max_path_sweep: the distances cover only
  // the path up to segment `stopped_segment`, fraction `stopped_s`.
  bool complete = true;
  int stopped_segment = 0;
  double stopped_s = 0;
  // True when the walk ended at a sample below SegmentCheckOptions::stop_below: the figures
  // cover the path up to that sample (segment, s), and min_distance is below stop_below.
  bool stopped_below = false;
};

// Checks straight segments q(s) = q0 + s (q1 − q0), s ∈ [0, 1], with obstacle time
// t(s) = t0 + s (t1 − t0). Built once per Model; check() allocates nothing.
class SegmentChecker {
 public:
  explicit SegmentChecker(const dynamics::Model& model, SegmentCheckOptions options = {});

  // Minimum signed distance along the segment; overwrites data with the last sample's
  // kinematics. Moving obstacles are taken at the interpolated time of each sample.
  SegmentCheckResult check(CollisionWorld& world, dynamics::Data& data,
                           const Eigen::Ref<const Eigen::VectorXd>& q0,
                           const Eigen::Ref<const Eigen::VectorXd>& q1, double t0 = 0,
                           double t1 = 0);
  // Minimum signed distance along the polyline through the rows of `path` (row i at obstacle
  // time times[i]; `times` empty = all at 0) by conservative advancement, pair by pair: a pair
  // at distance (or lower bound) d at a sample lets the walk on until its own geometry could
  // have closed d − clearance, counting only the joints that move one of its geometries
  // relative to the other; the next sample is where the first pair's allowance runs out (at
  // least max_sweep_step of the whole robot's sweep on, and at most max_time_step later when
  // obstacles move). So no stretch where a pair could come closer than `clearance` is skipped,
  // yet clear stretches, and stretches whose near pairs barely move, cost one query. Allocates
  // nothing after the first call with a given joint count and pair count. Stops after
  // max_path_samples queries or max_path_sweep of sweep (complete false), and at the first
  // sample below stop_below (stopped_below true).
  // A curved path sampled at the rows: `deviation` (one row per segment, one column per joint)
  // bounds how far each joint of the true path strays from the straight segment between two
  // rows (rad; m for prismatic joints). Each pair's allowance on a segment then shrinks by what
  // that stray could close of it, and a sample's distance is the least, over the pairs near
  // enough, of what each could come to, so the figures and the walk hold for the curve. Empty:
  // the path is the polyline.
  // Throws std::invalid_argument when `deviation` is neither empty nor segments × joints.
  PathCheckResult check_path(
      CollisionWorld& world, dynamics::Data& data, const Eigen::Ref<const Eigen::MatrixXd>& path,
      const std::vector<double>& times = {}, double clearance = 0,
      const Eigen::Ref<const Eigen::MatrixXd>& deviation = Eigen::MatrixXd());
  // Number of intervals the segment is cut into (samples − 1); the time span counts only
  // when there are moving obstacles.
  int intervals(const Eigen::Ref<const Eigen::VectorXd>& q0,
                const Eigen::Ref<const Eigen::VectorXd>& q1, double time_span = 0) const;
  // Bound on |∂p/∂q_j| over every point p of the robot's collision geometry (m/rad; 1 for a
  // prismatic joint), valid at any configuration.
  const Eigen::VectorXd& lever() const { return lever_; }

 private:
  // Fills pair_lever_ for pairs_: per pair and joint, how fast the joint can change the pair's
  // distance (m/rad).
  void set_pair_levers();

  const dynamics::Model& model_;
  SegmentCheckOptions options_;
  Eigen::VectorXd lever_;
  // Per robot geometry (row) and joint: the same bound for that geometry's points alone (0 for
  // joints that do not move it).
  Eigen::MatrixXd geom_lever_;
  Eigen::VectorXd q_;
  // check_path's work: the world's pairs; per pair and joint the bound on how fast a joint
  // changes the pair's distance; per pair its rate on the segment, allowance, bounds at the
  // last and the next sample, and what the stretch used of the allowance.
  std::vector<CollisionWorld::PairIndex> pairs_;
  Eigen::MatrixXd pair_lever_;
  // With a curved path, per segment the most its stray moves a point of the robot.
  Eigen::VectorXd rate_, allowance_, last_bound_, used_, dq_, seg_stray_;
  std::vector<char> ancestor_;
};

}  // namespace kinograph::collision

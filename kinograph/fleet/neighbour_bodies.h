#pragma once
// A neighbouring robot's collision bodies as obstacles of this robot's planner: standing still at
// a measured state, or moving along the neighbour's published plan on this robot's clock.
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "kinograph/collision/obstacle.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/trajectory_sampler.h"

namespace kinograph::fleet {

/// A robot sharing the workspace as another robot sees it: its name and its model placed at its
/// base in the common world (payload attached), whose collision geometry is what to keep clear of.
struct Neighbour {
  std::string name;
  std::shared_ptr<const dynamics::Model> model;
};

/// One collision geometry of a neighbour as an obstacle (shape and pose or trajectory), with the
/// name failure reasons use.
struct NeighbourBody {
  collision::Obstacle obstacle;
  std::string name;  ///< e.g. "neighbour 'right' link 'iiwa_link_4'"
};

/// How a neighbour's plan is sampled into pose trajectories.
struct SweepOptions {
  /// Samples per plan interval (its knot and samples_per_interval − 1 evenly between); poses
  /// between samples are interpolated by collision::PoseTrajectory. Default 10, as many as the
  /// validator checks per interval.
  int samples_per_interval = 10;
  /// Obstacle id of the neighbour's first collision geometry; geometry g gets first_id + g.
  /// Default 0.
  int first_id = 0;
};

/// "neighbour 'NAME' link 'LINK'": the name of one of a neighbour's collision geometries.
std::string body_name(const std::string& neighbour, const dynamics::Geometry& geometry);

/// Seconds from the clock origin `origin_utime` to `utime` (both µs on the robots' common clock):
/// the offset that puts a neighbour's plan time (plan_t start_utime + t) on one's own plan clock.
double clock_offset(std::int64_t utime, std::int64_t origin_utime);

/// A plan's configuration at plan time `tau` on its interpolant (`sampler` reads `plan`), at its
/// first knot before it starts and at its last knot after it ends.
Eigen::VectorXd held_configuration(const planning::Plan& plan,
                                   planning::TrajectorySampler& sampler, double tau);

/// The neighbour's bodies standing still at configuration q (one per collision geometry, ids
/// from first_id). Throws std::invalid_argument when q is not one finite value per joint.
std::vector<NeighbourBody> bodies_at(const Neighbour& neighbour, const Eigen::VectorXd& q,
                                     int first_id = 0);

/// Own-clock times at which bodies_along samples `plan`: every knot and samples_per_interval − 1
/// points between consecutive knots, each plan time shifted by `offset` seconds.
/// Throws std::invalid_argument when samples_per_interval < 1.
std::vector<double> sweep_times(const planning::Plan& plan, double offset,
                                int samples_per_interval);

/// The neighbour's bodies moving along `plan` (on its interpolant), sampled at the own-clock
/// `times` (strictly increasing); plan time τ is own time offset + τ. Before the plan starts the
/// bodies stand at its first knot, after it ends at its last. Geometry fixed to the neighbour's
/// base stays a static obstacle. Throws std::invalid_argument naming the neighbour when the plan
/// does not fit its model (as planning::TrajectorySampler) or the times do not increase.
std::vector<NeighbourBody> bodies_along(const Neighbour& neighbour, const planning::Plan& plan,
                                        double offset, const std::vector<double>& times,
                                        int first_id = 0);

/// bodies_along at sweep_times(plan, offset, options.samples_per_interval).
std::vector<NeighbourBody> bodies_along(const Neighbour& neighbour, const planning::Plan& plan,
                                        double offset, const SweepOptions& options = {});

}  // namespace kinograph::fleet

#include "kinograph/collision/segment_checker.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "kinograph/collision/convex_shape.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/graph/cancellation.h"

namespace kinograph::collision {
namespace {

// Largest distance a body's frame origin can be from its parent's: fixed for a revolute
// joint; a prismatic joint adds its travel (0 with a warning when unlimited).
double link_length(const dynamics::Body& body) {
  double len = body.parent_to_joint.translation().norm();
  if (body.joint_type == dynamics::JointType::kPrismatic) {
    const double travel = std::max(std::abs(body.limits.lower), std::abs(body.limits.upper));
    if (std::isfinite(travel)) {
      len += travel;
    } else {
      spdlog::warn(
          "segment checker: prismatic joint '{}' has no limits; its travel is not in "
          "the sweep bound",
          body.joint_name);
    }
  }
  return len;
}

}  // namespace

SegmentChecker::SegmentChecker(const dynamics::Model& model, SegmentCheckOptions options)
    : model_(model),
      options_(options),
      lever_(Eigen::VectorXd::Zero(model.nq())),
      geom_lever_(Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(model.collision.size()),
                                        model.nq())),
      q_(model.nq()) {
  // For each geometry, walk up its chain: the distance from joint j's axis point (body j's
  // origin) to any point of the geometry is at most the geometry's reach in its own body plus
  // the lengths of the links between.
  for (size_t i = 0; i < model.collision.size(); ++i) {
    const dynamics::Geometry& g = model.collision[i];
    if (g.body < 0) continue;
    const ConvexShape shape(shape_of(g));
    double reach = (g.origin * shape.bound_center()).norm() + shape.bound_radius();
    for (int b = g.body; b >= 0; b = model.bodies[b].parent) {
      const bool prismatic = model.bodies[b].joint_type == dynamics::JointType::kPrismatic;
      geom_lever_(static_cast<Eigen::Index>(i), b) = prismatic ? 1.0 : reach;
      lever_[b] = std::max(lever_[b], geom_lever_(static_cast<Eigen::Index>(i), b));
      reach += link_length(model.bodies[b]);
    }
  }
}

int SegmentChecker::intervals(const Eigen::Ref<const Eigen::VectorXd>& q0,
                              const Eigen::Ref<const Eigen::VectorXd>& q1, double time_span) const {
  double max_step = 0, sweep = 0;
  for (int j = 0; j < model_.nq(); ++j) {
    const double dq = std::abs(q1[j] - q0[j]);
    max_step = std::max(max_step, dq);
    sweep += dq * lever_[j];
  }
  const double n = std::max({1.0, std::ceil(max_step / options_.max_joint_step),
                             std::ceil(sweep / options_.max_sweep_step),
                             std::ceil(std::abs(time_span) / options_.max_time_step)});
  return static_cast<int>(std::min(n, 1e6));
}

SegmentCheckResult SegmentChecker::check(CollisionWorld& world, dynamics::Data& data,
                                         const Eigen::Ref<const Eigen::VectorXd>& q0,
                                         const Eigen::Ref<const Eigen::VectorXd>& q1, double t0,
                                         double t1) {
  SegmentCheckResult result;
  result.min_distance = std::numeric_limits<double>::infinity();
  const int n = intervals(q0, q1, world.has_moving_obstacles() ? t1 - t0 : 0.0);
  for (int k = 0; k <= n; ++k) {
    const double s = static_cast<double>(k) / n;
    q_ = q0 + s * (q1 - q0);
    dynamics::forward_kinematics(model_, data, q_);
    const Proximity p = world.closest(data, t0 + s * (t1 - t0));
    if (p.distance < result.min_distance) {
      result.min_distance = p.distance;
      result.s = s;
      result.closest = p;
    }
  }
  result.samples = n + 1;
  return result;
}

void SegmentChecker::set_pair_levers() {
  // Against an obstacle: the geometry's own lever. Between two geometries: joints that move both
  // alike change nothing, so only the joints below their common ancestor count, each with the
  // lever of the geometry it moves.
  const int pair_count = static_cast<int>(pairs_.size()), nq = model_.nq();
  pair_lever_.setZero(pair_count, nq);
  ancestor_.resize(static_cast<size_t>(nq));
  auto mark_chain = [&](int g) {
    std::fill(ancestor_.begin(), ancestor_.end(), 0);
    for (int b = model_.collision[static_cast<size_t>(g)].body; b >= 0; b = model_.bodies[b].parent)
      ancestor_[static_cast<size_t>(b)] = 1;
  };
  auto add_chain_outside = [&](int k, int g) {  // g's joints not marked in ancestor_
    for (int b = model_.collision[static_cast<size_t>(g)].body; b >= 0;
         b = model_.bodies[b].parent) {
      if (!ancestor_[static_cast<size_t>(b)]) pair_lever_(k, b) += geom_lever_(g, b);
    }
  };
  for (int k = 0; k < pair_count; ++k) {
    const CollisionWorld::PairIndex& pr = pairs_[static_cast<size_t>(k)];
    if (!pr.self) {
      pair_lever_.row(k) = geom_lever_.row(pr.a);
      continue;
    }
    mark_chain(pr.b);
    add_chain_outside(k, pr.a);
    mark_chain(pr.a);
    add_chain_outside(k, pr.b);
  }
}

PathCheckResult SegmentChecker::check_path(CollisionWorld& world, dynamics::Data& data,
                                           const Eigen::Ref<const Eigen::MatrixXd>& path,
                                           const std::vector<double>& times, double clearance,
                                           const Eigen::Ref<const Eigen::MatrixXd>& deviation) {
  PathCheckResult result;
  result.min_distance = result.lower_bound = std::numeric_limits<double>::infinity();
  const int m = static_cast<int>(path.rows());
  const bool curved = deviation.size() > 0;
  if (curved && (deviation.rows() != m - 1 || deviation.cols() != model_.nq())) {
    throw std::invalid_argument("check_path: the deviation must have one row per segment (" +
                                std::to_string(std::max(0, m - 1)) +
                                ") and one column per joint (" + std::to_string(model_.nq()) + ")");
  }
  if (m == 0) return result;
  const bool moving = world.has_moving_obstacles();
  auto time_at = [&](int i, double u) {
    if (times.empty()) return 0.0;
    return i + 1 < m ? times[i] + u * (times[i + 1] - times[i]) : times[i];
  };
  world.closest_pairs(pairs_);
  const int pair_count = static_cast<int>(pairs_.size()), nq = model_.nq();
  set_pair_levers();
  rate_.resize(pair_count);
  allowance_.resize(pair_count);
  last_bound_.resize(pair_count);
  used_.resize(pair_count);
  dq_.resize(nq);
  // The whole robot's sweep: any point moves at most it, two points approach by at most twice
  // it. It sets the least step and the sweep bound.
  const double relative = world.self_pairs().empty() ? 1.0 : 2.0;
  auto sweep_of = [&](int i) {
    return relative * (path.row(i + 1) - path.row(i)).cwiseAbs().dot(lever_.transpose());
  };
  // Per segment the most its stray could move a point of the robot (the whole robot's bound;
  // two geometries approach by at most twice it). A pair's own share costs a dot product and
  // is asked only of pairs near enough to need it.
  if (curved) seg_stray_.noalias() = deviation.cwiseAbs() * lever_;
  auto stray_on = [&](int i) { return curved && i < m - 1 ? seg_stray_[i] : 0.0; };
  auto pair_stray = [&](int k, int i) {
    return pair_lever_.row(k).dot(deviation.row(i).cwiseAbs());
  };
  auto sample = [&](int i, double u) {
    if (i + 1 < m) {
      q_ = path.row(i).transpose() + u * (path.row(i + 1) - path.row(i)).transpose();
    } else {
      q_ = path.row(i).transpose();
    }
    // A long walk (a fine plan's validation) must not hold up a daemon that stops its plan.
    graph::throw_if_cancelled();
    dynamics::forward_kinematics(model_, data, q_);
    ++result.samples;
    const Proximity p = world.closest(data, time_at(i, u));
    // Off the rows the curve may be closer than the segment by its stray: each pair near
    // enough to matter counts its own, from at least the closest pair's distance. A sample
    // that cannot come below the smallest so far is left as it is.
    double distance = p.distance;
    const int seg = std::min(i, m - 2);
    const double stray = stray_on(seg);
    if (stray > 0 && p.distance - relative * stray < result.min_distance) {
      const std::span<const double> bounds = world.pair_bounds();
      for (int k = 0; k < pair_count; ++k) {
        if (bounds[static_cast<size_t>(k)] < p.distance + relative * stray) {
          distance = std::min(
              distance, std::max(bounds[static_cast<size_t>(k)], p.distance) - pair_stray(k, seg));
        }
      }
    }
    if (distance < result.min_distance) {
      result.min_distance = distance;
      result.segment = i;
      result.s = u;
      result.closest = p;
    }
  };

  int i = 0;     // current segment
  double u = 0;  // fraction along it
  sample(0, 0);
  last_bound_ = Eigen::Map<const Eigen::VectorXd>(world.pair_bounds().data(), pair_count);
  result.stopped_below = result.min_distance < options_.stop_below;
  if (m == 1 || result.stopped_below) {
    result.lower_bound = result.min_distance;
    return result;
  }
  while (i < m - 1) {
    // Each pair's allowance to the next sample, the least step, and with moving obstacles a
    // time budget.
    allowance_ = last_bound_.array() - clearance;
    used_.setZero();
    double least = options_.max_sweep_step;
    double time_budget = moving ? options_.max_time_step : std::numeric_limits<double>::infinity();
    double swept = 0, stretch_stray = 0;
    bool at_start = true;  // the stretch has not moved from its sample yet
    while (i < m - 1) {
      dq_ = (path.row(i + 1) - path.row(i)).cwiseAbs().transpose();
      rate_.noalias() = pair_lever_ * dq_;
      const double stray = stray_on(i);
      stretch_stray = std::max(stretch_stray, relative * stray);
      const double seg_sweep = sweep_of(i);
      const double seg_time = std::abs(time_at(i, 1) - time_at(i, 0));
      const double left = 1 - u;
      // The fraction of this segment the budgets allow: until the first pair's allowance, less
      // what the segment's stray could close, runs out, but at least the least step.
      // A pair whose distance this segment cannot change sets no limit; an allowance that is
      // not a number allows nothing.
      double by_pairs = left;
      const double whole = relative * stray;
      for (int k = 0; k < pair_count; ++k) {
        // The whole robot's bound first; the pair's own share only where that one limits.
        if (rate_[k] * left <= allowance_[k] - whole) continue;
        const double own = stray > 0 ? pair_stray(k, i) : 0.0, room = allowance_[k] - own;
        if ((rate_[k] > 0 || own > 0) && !(rate_[k] * left <= room)) {
          by_pairs = std::min(by_pairs, room > 0 && rate_[k] > 0 ? room / rate_[k] : 0.0);
        }
      }
      const double by_least =
          seg_sweep * left > least ? std::max(0.0, least) / seg_sweep : left;
      double f = std::max(by_pairs, by_least);
      // A segment whose stray could close a pair's allowance starts with a sample, which counts
      // that stray, even where its straight part does not move.
      if (curved && by_pairs <= 0 && !at_start) f = 0;
      at_start = at_start && f <= 0;
      if (moving && seg_time * left > time_budget) f = std::min(f, time_budget / seg_time);
      allowance_ -= f * rate_;
      used_ += f * rate_;
      least -= seg_sweep * f;
      time_budget -= seg_time * f;
      swept += seg_sweep * f;
      if (f < left) {
        u += f;
        break;
      }
      ++i;
      u = 0;
      // A spent allowance stops the walk in the next segment that moves its pair.
      if (i == m - 1 || time_budget <= 0) break;
    }
    result.swept += swept / relative;
    if (result.samples >= options_.max_path_samples || result.swept > options_.max_path_sweep) {
      result.complete = false;
      result.stopped_segment = i;
      result.stopped_s = u;
      break;
    }
    sample(i, u);
    // Along the stretch each pair stays at least (d_a + d_b − its sweep) / 2 away.
    const auto next = Eigen::Map<const Eigen::VectorXd>(world.pair_bounds().data(), pair_count);
    if (pair_count > 0) {
      result.lower_bound = std::min(result.lower_bound,
                                    0.5 * (last_bound_ + next - used_).minCoeff() - stretch_stray);
    }
    last_bound_ = next;
    if (result.min_distance < options_.stop_below) {
      result.stopped_below = true;
      break;
    }
  }
  result.lower_bound = std::min(result.lower_bound, result.min_distance);
  return result;
}

}  // namespace kinograph::collision

#include "kinograph/planning/goal_sampler.h"

#include <cmath>
#include <stdexcept>

#include "kinograph/collision/collision_world.h"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/clearance_world.h"

namespace kinograph::planning {

GoalSampler::GoalSampler(const Problem& problem, GoalSamplerOptions options)
    : problem_(problem), options_(std::move(options)), rng_(options_.seed) {
  if (!problem_.model) throw std::invalid_argument("GoalSampler: the problem has no robot model");
  const dynamics::Model& model = *problem_.model;
  clearance_ = options_.clearance < 0 ? problem_.objectives.collision_epsilon : options_.clearance;
  if (!options_.region_frame.empty()) {
    region_frame_ = -1;
    for (std::size_t f = 0; f < model.frames.size(); ++f) {
      if (model.frames[f].name == options_.region_frame) region_frame_ = static_cast<int>(f);
    }
    if (region_frame_ < 0) {
      throw std::invalid_argument("GoalSampler: no frame '" + options_.region_frame + "'");
    }
  }
  lo_.resize(model.nq());
  hi_.resize(model.nq());
  for (int j = 0; j < model.nq(); ++j) {
    const dynamics::JointLimits& l = model.bodies[j].limits;
    lo_[j] = std::isfinite(l.lower) ? l.lower + options_.limit_margin : -M_PI;
    hi_[j] = std::isfinite(l.upper) ? l.upper - options_.limit_margin : M_PI;
    if (lo_[j] > hi_[j]) lo_[j] = hi_[j] = 0.5 * (l.lower + l.upper);
  }
  data_ = std::make_unique<dynamics::Data>(model);
  world_ = std::make_unique<collision::CollisionWorld>(model);
  for (const collision::Obstacle& o : problem_.obstacles) {
    const collision::Status status = world_->add_obstacle(o);
    if (!status) throw std::invalid_argument("GoalSampler: " + status.reason);
  }
  if (problem_.self_and_floor.floor)
    world_->add_obstacle(floor_obstacle(*problem_.self_and_floor.floor));
  if (options_.self_collision) {
    collision::CollisionWorldOptions self;
    self.self_collision = true;
    self.self_collision_excluded = options_.self_collision_excluded;
    self_world_ = std::make_unique<collision::CollisionWorld>(model, self);
  }
}

GoalSampler::~GoalSampler() = default;

bool GoalSampler::accepts(const Eigen::VectorXd& q) {
  const dynamics::Model& model = *problem_.model;
  if (q.size() != model.nq()) return false;
  for (int j = 0; j < model.nq(); ++j) {
    if (!(q[j] >= lo_[j] && q[j] <= hi_[j])) return false;
  }
  dynamics::forward_kinematics(model, *data_, q);
  if (region_frame_ >= 0 &&
      !options_.region.contains(dynamics::frame_pose(model, *data_, region_frame_).translation())) {
    return false;
  }
  if (world_->num_obstacles() > 0 &&
      world_->closest(*data_, problem_.horizon).distance < clearance_) {
    return false;
  }
  if (self_world_ && self_world_->closest(*data_).distance < options_.self_clearance) {
    return false;
  }
  return true;
}

std::optional<Eigen::VectorXd> GoalSampler::sample() {
  const int n = problem_.model->nq();
  Eigen::VectorXd q(n);
  for (int attempt = 0; attempt < options_.max_attempts; ++attempt) {
    ++attempts_;
    for (int j = 0; j < n; ++j) q[j] = std::uniform_real_distribution<double>(lo_[j], hi_[j])(rng_);
    if (accepts(q)) return q;
  }
  return std::nullopt;
}

std::vector<Eigen::VectorXd> GoalSampler::sample(int count) {
  std::vector<Eigen::VectorXd> goals;
  for (int i = 0; i < count; ++i) {
    std::optional<Eigen::VectorXd> q = sample();
    if (!q) break;
    goals.push_back(*q);
  }
  return goals;
}

}  // namespace kinograph::planning

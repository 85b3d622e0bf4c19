#include "kinograph/graph/prior_factor.h"

#include <stdexcept>

namespace kinograph::graph {

PriorFactor::PriorFactor(Key key, const Eigen::Ref<const Eigen::VectorXd>& target,
                         NoiseModelPtr noise)
    : Factor({key}, {static_cast<int>(target.size())}, static_cast<int>(target.size()),
             std::move(noise)),
      target_(target) {
  set_linear();
}

void PriorFactor::evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                           const Jacobians* J) const {
  e = x[0] - target_;
  if (J) J->block(0).setIdentity();
}

void PriorFactor::set_target(const Eigen::Ref<const Eigen::VectorXd>& target) {
  if (target.size() != target_.size()) {
    throw std::invalid_argument("PriorFactor::set_target: size " + std::to_string(target.size()) +
                                " for a prior of size " + std::to_string(target_.size()));
  }
  target_ = target;
}

}  // namespace kinograph::graph

#pragma once
// A prior on one vector variable: e = x − target (start and goal states, regularizers).
#include <Eigen/Core>

#include "kinograph/graph/factor.h"

namespace kinograph::graph {

/// e = x − target. The target may be changed between solves without rebuilding structure.
class PriorFactor final : public Factor {
 public:
  PriorFactor(Key key, const Eigen::Ref<const Eigen::VectorXd>& target,
              NoiseModelPtr noise = nullptr);

  void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const Jacobians* J) const override;
  bool parallel_safe() const override { return true; }  // touches only its own state

  const Eigen::VectorXd& target() const { return target_; }
  /// Throws std::invalid_argument if the size differs.
  void set_target(const Eigen::Ref<const Eigen::VectorXd>& target);

 private:
  Eigen::VectorXd target_;
};

}  // namespace kinograph::graph

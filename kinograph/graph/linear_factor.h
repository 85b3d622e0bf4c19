#pragma once
// A linear factor e = Σ_i A_i x_i − b: linear least squares, and a test bed for the solvers.
#include <Eigen/Core>
#include <vector>

#include "kinograph/graph/factor.h"

namespace kinograph::graph {

/// e = Σ_i A_i x_i − b with one matrix A_i per key (all with b's number of rows).
class LinearFactor final : public Factor {
 public:
  /// Throws std::invalid_argument if the sizes disagree.
  LinearFactor(std::vector<Key> keys, std::vector<Eigen::MatrixXd> A, Eigen::VectorXd b,
               NoiseModelPtr noise = nullptr);

  void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const Jacobians* J) const override;
  bool parallel_safe() const override { return true; }  // touches only its own state

  const std::vector<Eigen::MatrixXd>& A() const { return A_; }
  const Eigen::VectorXd& b() const { return b_; }
  /// Throws std::invalid_argument if the size differs.
  void set_b(const Eigen::Ref<const Eigen::VectorXd>& b);

 private:
  std::vector<Eigen::MatrixXd> A_;
  Eigen::VectorXd b_;
};

}  // namespace kinograph::graph

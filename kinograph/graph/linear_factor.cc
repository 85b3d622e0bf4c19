#include "kinograph/graph/linear_factor.h"

#include <stdexcept>

namespace kinograph::graph {

namespace {
std::vector<int> column_counts(const std::vector<Eigen::MatrixXd>& A) {
  std::vector<int> dims;
  for (const auto& a : A) dims.push_back(static_cast<int>(a.cols()));
  return dims;
}
}  // namespace

LinearFactor::LinearFactor(std::vector<Key> keys, std::vector<Eigen::MatrixXd> A, Eigen::VectorXd b,
                           NoiseModelPtr noise)
    : Factor(std::move(keys), column_counts(A), static_cast<int>(b.size()), std::move(noise)),
      A_(std::move(A)),
      b_(std::move(b)) {
  for (size_t i = 0; i < A_.size(); ++i) {
    if (A_[i].rows() != b_.size()) {
      throw std::invalid_argument("LinearFactor: A[" + std::to_string(i) + "] has " +
                                  std::to_string(A_[i].rows()) + " rows, b has " +
                                  std::to_string(b_.size()));
    }
  }
  set_linear();
}

void LinearFactor::evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                            const Jacobians* J) const {
  e = -b_;
  for (size_t i = 0; i < A_.size(); ++i) {
    e.noalias() += A_[i] * x[static_cast<int>(i)];
    if (J) J->block(static_cast<int>(i)) = A_[i];
  }
}

void LinearFactor::set_b(const Eigen::Ref<const Eigen::VectorXd>& b) {
  if (b.size() != b_.size()) {
    throw std::invalid_argument("LinearFactor::set_b: size " + std::to_string(b.size()) +
                                " for a factor of size " + std::to_string(b_.size()));
  }
  b_ = b;
}

}  // namespace kinograph::graph

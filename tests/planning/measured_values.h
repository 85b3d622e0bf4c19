#pragma once
// The raw values of a collision factor with every pair it reports measured. An evaluation
// without Jacobians and multipliers measures only the pairs within their ε (the others' hinges
// are off at any distance); one with Jacobians measures every pair within the query distance.
#include <Eigen/Core>
#include <vector>

#include "kinograph/graph/factor.h"
#include "kinograph/graph/values.h"
#include "kinograph/planning/factors/constrained_factor.h"

namespace kinograph::planning::testing {

/// compute() at x with a Jacobian (discarded), for its raw values.
inline Eigen::VectorXd measured_values(const ConstrainedFactor& f, const graph::FactorValues& x) {
  Eigen::VectorXd z = Eigen::VectorXd::Zero(f.residual_dim());
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(f.residual_dim(), f.jacobian_cols());
  const graph::Jacobians jacobians(J.data(), J.rows(), J.rows(), f.block_offsets().data(),
                                   f.dims().data());
  f.compute(x, z, &jacobians);
  return z;
}

/// The same at `v`.
inline Eigen::VectorXd measured_values(const ConstrainedFactor& f, const graph::Values& v) {
  std::vector<const double*> ptrs;
  for (const graph::Key& k : f.keys()) ptrs.push_back(v.at(k).data());
  return measured_values(f, graph::FactorValues(ptrs.data(), f.dims().data()));
}

}  // namespace kinograph::planning::testing

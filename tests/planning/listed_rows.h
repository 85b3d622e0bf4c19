#pragma once
// A factor linearized the way a solver that takes row lists linearizes it: into a Jacobian
// filled with anything beforehand, for tests of factors that write only the rows they list.
#include <Eigen/Core>
#include <vector>

#include "kinograph/graph/factor.h"
#include "kinograph/graph/values.h"

namespace kinograph::planning::testing {

/// Whitened residual, Jacobian and row list of one linearization.
struct Linearization {
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  graph::RowSupport support;
};

/// whitened() at v into a J filled with `fill`, with or without a row list.
inline Linearization linearize(const graph::Factor& f, const graph::Values& v, double fill,
                               bool with_list) {
  std::vector<const double*> ptrs;
  for (const graph::Key& k : f.keys()) ptrs.push_back(v.at(k).data());
  Linearization l{Eigen::VectorXd::Zero(f.residual_dim()),
                  Eigen::MatrixXd::Constant(f.residual_dim(), f.jacobian_cols(), fill), {}};
  Eigen::Ref<Eigen::MatrixXd> J(l.J);
  f.whitened(ptrs.data(), l.r, &J, with_list ? &l.support : nullptr);
  return l;
}

}  // namespace kinograph::planning::testing

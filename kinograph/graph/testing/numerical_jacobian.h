#pragma once
// Jacobian checker for tests of every module: compares a factor's analytic Jacobian blocks with
// central differences, block by block. Header-only; no test framework dependency, so use it as
//   auto check = check_jacobians(factor, values);  EXPECT_TRUE(check.ok) << check.report();
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "kinograph/graph/factor.h"
#include "kinograph/graph/values.h"

namespace kinograph::graph::testing {

/// Options of check_jacobians.
struct JacobianCheckOptions {
  double step = 1e-6;       ///< central-difference step h (per scalar coordinate)
  double tolerance = 1e-5;  ///< a block passes if max|A−N| ≤ tolerance·max(1, max|N|)
  bool whitened = false;    ///< check r = noise(e) instead of the raw error e (hinges have kinks)
};

/// Deviation of one key's block.
struct BlockCheck {
  Key key;
  double max_abs_error = 0;  ///< max |analytic − numeric|
  double max_rel_error = 0;  ///< max_abs_error / max(1, max |numeric|)
  Eigen::MatrixXd analytic;
  Eigen::MatrixXd numeric;
  bool ok = true;
};

/// Result of check_jacobians: overall verdict and per-block errors.
struct JacobianCheck {
  bool ok = true;
  double max_abs_error = 0;
  double max_rel_error = 0;
  std::vector<BlockCheck> blocks;

  /// Multi-line description naming the failing blocks, with both matrices.
  std::string report() const {
    std::ostringstream os;
    os << (ok ? "Jacobians match" : "Jacobian mismatch") << " (max abs " << max_abs_error
       << ", max rel " << max_rel_error << ")\n";
    for (const auto& b : blocks) {
      os << "  block " << b.key.to_string() << ": abs " << b.max_abs_error << ", rel "
         << b.max_rel_error << (b.ok ? "" : "  <-- FAILS") << "\n";
      if (!b.ok) {
        os << "  analytic:\n" << b.analytic << "\n  numeric:\n" << b.numeric << "\n";
      }
    }
    return os.str();
  }
};

/// Compares factor's Jacobian blocks at `values` with central differences of its (raw or
/// whitened) error. Throws std::out_of_range if a key is missing from `values`.
inline JacobianCheck check_jacobians(const Factor& factor, const Values& values,
                                     const JacobianCheckOptions& options = {}) {
  const auto& keys = factor.keys();
  const int m = factor.residual_dim();
  const int cols = factor.jacobian_cols();
  std::vector<Eigen::VectorXd> x(keys.size());
  for (size_t i = 0; i < keys.size(); ++i) x[i] = values.at(keys[i]);
  std::vector<const double*> ptrs(keys.size());
  auto eval = [&](Eigen::VectorXd& e, Eigen::MatrixXd* J) {
    for (size_t i = 0; i < keys.size(); ++i) ptrs[i] = x[i].data();
    e.setZero(m);
    if (J == nullptr) {
      if (options.whitened) {
        factor.whitened(ptrs.data(), e, nullptr);
      } else {
        factor.evaluate(FactorValues(ptrs.data(), factor.dims().data()), e, nullptr);
      }
      return;
    }
    J->setZero(m, cols);
    if (options.whitened) {
      Eigen::Ref<Eigen::MatrixXd> ref(*J);
      factor.whitened(ptrs.data(), e, &ref);
    } else {
      Jacobians jac(J->data(), m, m, factor.block_offsets().data(), factor.dims().data());
      factor.evaluate(FactorValues(ptrs.data(), factor.dims().data()), e, &jac);
    }
  };
  Eigen::VectorXd e0, ep, em;
  Eigen::MatrixXd J;
  eval(e0, &J);
  JacobianCheck result;
  for (size_t i = 0; i < keys.size(); ++i) {
    BlockCheck block;
    block.key = keys[i];
    const int d = factor.dims()[i];
    block.analytic = J.middleCols(factor.block_offsets()[i], d);
    block.numeric.resize(m, d);
    for (int k = 0; k < d; ++k) {
      const double saved = x[i][k];
      x[i][k] = saved + options.step;
      eval(ep, nullptr);
      x[i][k] = saved - options.step;
      eval(em, nullptr);
      x[i][k] = saved;
      block.numeric.col(k) = (ep - em) / (2 * options.step);
    }
    block.max_abs_error = m == 0 ? 0 : (block.analytic - block.numeric).cwiseAbs().maxCoeff();
    const double scale = std::max(1.0, m == 0 ? 0.0 : block.numeric.cwiseAbs().maxCoeff());
    block.max_rel_error = block.max_abs_error / scale;
    block.ok = std::isfinite(block.max_abs_error) && block.max_rel_error <= options.tolerance;
    result.ok = result.ok && block.ok;
    result.max_abs_error = std::max(result.max_abs_error, block.max_abs_error);
    result.max_rel_error = std::max(result.max_rel_error, block.max_rel_error);
    result.blocks.push_back(std::move(block));
  }
  return result;
}

}  // namespace kinograph::graph::testing

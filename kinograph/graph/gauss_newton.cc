#include "kinograph/graph/gauss_newton.h"

#include <algorithm>
#include <chrono>
#include <limits>

#include "kinograph/graph/cancellation.h"
#include "kinograph/graph/normal_equations.h"
#include "kinograph/graph/stopwatch.h"

namespace kinograph::graph {

namespace {
using Clock = std::chrono::steady_clock;
}  // namespace

GaussNewton::GaussNewton(GaussNewtonOptions options) : options_(options) {}
GaussNewton::~GaussNewton() = default;

OptimizationResult GaussNewton::optimize(const FactorGraph& graph, Values& values) {
  const auto t_start = Clock::now();
  const GaussNewtonOptions& o = options_;
  OptimizationResult result;
  if (!equations_ || !equations_->matches(graph, values)) {
    cholesky_.reset();
    equations_ = std::make_unique<NormalEquations>(graph, values, o.ordering);
    if (equations_->dim() > 0) {
      cholesky_ = std::make_unique<SparseCholesky>(equations_->dim(), equations_->col_ptr(),
                                                   equations_->row_idx(), o.factorization);
    }
    result.symbolic_s = seconds_since(t_start);
  }
  NormalEquations& eq = *equations_;
  auto finish = [&](SolverStatus status, std::string reason) {
    result.status = status;
    result.reason = std::move(reason);
    result.total_s = seconds_since(t_start);
    return result;
  };

  double error = 0;
  std::string reason;
  Eigen::VectorXd step(eq.dim()), rhs(eq.dim()), x_backup;
  for (int it = 0; it < o.max_iterations; ++it) {
    throw_if_cancelled();
    IterationStats stats;
    stats.iteration = it;
    auto t = Clock::now();
    if (!eq.linearize(graph, values, &error, &reason)) {
      return finish(SolverStatus::kNonFinite, reason);
    }
    stats.linearize_s = seconds_since(t);
    result.linearize_s += stats.linearize_s;
    ++result.iterations;
    if (it == 0) result.initial_error = result.final_error = error;
    if (error <= o.absolute_error_tol) {
      return finish(SolverStatus::kConverged, "error at or below the absolute tolerance");
    }
    if (eq.dim() == 0) return finish(SolverStatus::kConverged, "no free variables");
    ++result.trials;
    t = Clock::now();
    std::copy(eq.hessian().begin(), eq.hessian().end(), cholesky_->values());
    const bool factored = cholesky_->factorize();
    stats.factorize_s = seconds_since(t);
    result.factorize_s += stats.factorize_s;
    if (!factored) {
      return finish(SolverStatus::kSingular,
                    "normal equations not positive definite at variable " +
                        eq.key_of_column(cholesky_->failed_column(), values).to_string());
    }
    t = Clock::now();
    rhs = -eq.gradient();
    cholesky_->solve(rhs, step);
    stats.solve_s = seconds_since(t);
    result.solve_s += stats.solve_s;
    stats.step_norm = step.norm();
    t = Clock::now();
    x_backup = values.vector();
    eq.add_step(step, values.vector());
    double new_error = 0;
    const bool finite = eq.evaluate_error(graph, values, &new_error, &reason);
    stats.evaluate_s = seconds_since(t);
    result.evaluate_s += stats.evaluate_s;
    stats.error = new_error;
    stats.accepted = finite && new_error <= error;
    if (o.record_history) result.history.push_back(stats);
    const double rounding = 8 * std::numeric_limits<double>::epsilon() * error;
    if (finite && !stats.accepted &&
        new_error - error <= std::max(o.relative_error_tol * error, rounding)) {
      // At the optimum rounding can make the last step a hair worse: that is convergence.
      values.vector() = x_backup;
      return finish(SolverStatus::kConverged, "relative change below tolerance");
    }
    if (!stats.accepted) {
      values.vector() = x_backup;
      return finish(SolverStatus::kNoDecrease,
                    finite ? "the Gauss-Newton step increased the error"
                           : "the Gauss-Newton step led to a non-finite residual: " + reason);
    }
    const double relative_decrease = error > 0 ? (error - new_error) / error : 0;
    result.final_error = new_error;
    if (new_error <= o.absolute_error_tol || relative_decrease < o.relative_error_tol) {
      return finish(SolverStatus::kConverged, "relative decrease below tolerance");
    }
  }
  return finish(SolverStatus::kMaxIterations,
                "reached " + std::to_string(o.max_iterations) + " iterations");
}

}  // namespace kinograph::graph

#include "kinograph/graph/levenberg_marquardt.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "kinograph/graph/normal_equations.h"

namespace kinograph::graph {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}
}  // namespace

LevenbergMarquardt::LevenbergMarquardt(LevenbergMarquardtOptions options) : options_(options) {}
LevenbergMarquardt::~LevenbergMarquardt() = default;
LevenbergMarquardt::LevenbergMarquardt(LevenbergMarquardt&&) noexcept = default;
LevenbergMarquardt& LevenbergMarquardt::operator=(LevenbergMarquardt&&) noexcept = default;

void LevenbergMarquardt::set_options(const LevenbergMarquardtOptions& options) {
  if (options.ordering != options_.ordering || options.factorization != options_.factorization) {
    equations_.reset();
    candidate_.reset();
    cholesky_.reset();
  }
  options_ = options;
}

OptimizationResult LevenbergMarquardt::optimize(const FactorGraph& graph, Values& values) {
  const auto t_start = Clock::now();
  const LevenbergMarquardtOptions& o = options_;
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
  if (o.linearize_at_evaluation && (!candidate_ || !candidate_->matches(graph, values))) {
    candidate_ = std::make_unique<NormalEquations>(*equations_);
  }
  NormalEquations& eq = *equations_;
  const int n = eq.dim();
  if (o.record_history) result.history.reserve(std::min(o.max_iterations, 64) * 2);

  auto finish = [&](SolverStatus status, std::string reason) {
    result.status = status;
    result.reason = std::move(reason);
    result.total_s = seconds_since(t_start);
    if (o.log_iterations) {
      spdlog::debug("LM: {} after {} iterations, error {:.6g} -> {:.6g}: {}", to_string(status),
                    result.iterations, result.initial_error, result.final_error, result.reason);
    }
    return result;
  };

  double error = 0;
  std::string reason;
  auto t = Clock::now();
  if (!eq.linearize(graph, values, &error, &reason)) {
    return finish(SolverStatus::kNonFinite, reason);
  }
  double linearize_s = seconds_since(t);
  result.linearize_s += linearize_s;
  result.initial_error = result.final_error = error;
  result.iterations = 1;
  if (error <= o.absolute_error_tol) {
    return finish(SolverStatus::kConverged, "error at or below the absolute tolerance");
  }
  if (n == 0) return finish(SolverStatus::kConverged, "no free variables");

  Eigen::VectorXd D(n), step(n), rhs(n), x_backup(values.vector().size());
  auto update_damping = [&]() {
    if (o.damping == Damping::kIdentity) {
      D.setOnes();
    } else {
      for (int c = 0; c < n; ++c) {
        D[c] = std::clamp(eq.hessian()[eq.diagonal_positions()[c]], o.min_diagonal, o.max_diagonal);
      }
    }
  };
  update_damping();

  double lambda = o.lambda_initial;
  double nu = 2;
  const std::vector<double>& h = eq.hessian();
  const std::vector<int>& diag = eq.diagonal_positions();
  while (true) {
    // One iteration: trials with growing λ until a step decreases the error.
    IterationStats stats;
    stats.iteration = result.iterations - 1;
    stats.linearize_s = linearize_s;
    linearize_s = 0;
    stats.lambda = lambda;
    ++result.trials;
    t = Clock::now();
    double* A = cholesky_->values();
    std::copy(h.begin(), h.end(), A);
    for (int c = 0; c < n; ++c) A[diag[c]] += lambda * D[c];
    const bool factored = cholesky_->factorize();
    stats.factorize_s = seconds_since(t);
    result.factorize_s += stats.factorize_s;
    bool accepted = false;
    bool converged = false;
    bool candidate_ready = false;
    if (factored) {
      t = Clock::now();
      rhs = -eq.gradient();
      cholesky_->solve(rhs, step);
      stats.solve_s = seconds_since(t);
      result.solve_s += stats.solve_s;
      stats.step_norm = step.norm();
      const double x_norm = values.vector().norm();
      if (!step.allFinite()) {
        // Treated like a failed factorization: more damping.
      } else if (stats.step_norm <= o.step_tol * (x_norm + o.step_tol)) {
        stats.error = error;
        if (o.record_history) result.history.push_back(stats);
        result.lambda = lambda;
        return finish(SolverStatus::kConverged, "step below the step tolerance");
      } else {
        // Model decrease ½(λδᵀDδ − gᵀδ) of the linearized cost for the step δ.
        const double predicted =
            0.5 * (lambda * step.dot(D.asDiagonal() * step) - eq.gradient().dot(step));
        t = Clock::now();
        x_backup = values.vector();
        eq.add_step(step, values.vector());
        double new_error = 0;
        candidate_ready =
            o.linearize_at_evaluation && candidate_->linearize(graph, values, &new_error, nullptr);
        // Without the candidate (or when its Jacobian is not finite) the error alone decides,
        // and a non-finite Jacobian is reported by the linearization after acceptance.
        const bool finite =
            candidate_ready || eq.evaluate_error(graph, values, &new_error, nullptr);
        stats.evaluate_s = seconds_since(t);
        result.evaluate_s += stats.evaluate_s;
        stats.error = finite ? new_error : std::numeric_limits<double>::infinity();
        // At the optimum both the model decrease and the actual change sink below the rounding
        // of the cost; such a step is as good as any and is kept, so LM can polish x to full
        // precision instead of mistaking rounding for a failed step.
        const double rounding = 8 * std::numeric_limits<double>::epsilon() * error;
        const bool at_rounding = predicted <= rounding && new_error - error <= rounding;
        if (finite && (new_error < error || at_rounding)) {
          accepted = true;
          const double rho =
              (predicted > 0 && !at_rounding) ? (error - new_error) / predicted : 1.0;
          lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
          lambda = std::max(lambda, o.lambda_min);
          nu = 2;
          const double relative_decrease = (error - new_error) / error;
          error = new_error;
          result.final_error = error;
          converged = relative_decrease < o.relative_error_tol || error <= o.absolute_error_tol;
        } else {
          values.vector() = x_backup;
        }
      }
    }
    stats.accepted = accepted;
    if (o.record_history) result.history.push_back(stats);
    if (o.log_iterations) {
      spdlog::debug("LM it {} λ={:.3g} |δ|={:.3g} error={:.9g} {}", stats.iteration, stats.lambda,
                    stats.step_norm, stats.error, accepted ? "accepted" : "rejected");
    }
    result.lambda = lambda;
    if (accepted) {
      if (converged) {
        return finish(SolverStatus::kConverged, error <= o.absolute_error_tol
                                                    ? "error at or below the absolute tolerance"
                                                    : "relative decrease below tolerance");
      }
      if (result.iterations >= o.max_iterations) {
        return finish(SolverStatus::kMaxIterations,
                      "reached " + std::to_string(o.max_iterations) + " iterations");
      }
      t = Clock::now();
      if (candidate_ready) {
        std::swap(eq, *candidate_);  // linearized at the accepted point already
      } else if (!eq.linearize(graph, values, &error, &reason)) {
        return finish(SolverStatus::kNonFinite, reason);
      }
      linearize_s = seconds_since(t);
      result.linearize_s += linearize_s;
      ++result.iterations;
      update_damping();
      continue;
    }
    lambda *= nu;
    nu *= 2;
    if (lambda > o.lambda_max) {
      result.lambda = lambda;
      if (!factored) {
        return finish(SolverStatus::kSingular,
                      "normal equations not positive definite at variable " +
                          eq.key_of_column(cholesky_->failed_column(), values).to_string() +
                          " even with lambda " + std::to_string(lambda / nu * 2));
      }
      return finish(SolverStatus::kNoDecrease,
                    "no step decreased the error up to lambda " + std::to_string(o.lambda_max));
    }
  }
}

}  // namespace kinograph::graph

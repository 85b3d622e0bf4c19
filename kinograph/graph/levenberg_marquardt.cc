#include "kinograph/graph/levenberg_marquardt.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "kinograph/graph/cancellation.h"
#include "kinograph/graph/envelope_cholesky.h"
#include "kinograph/graph/normal_equations.h"
#include "kinograph/graph/stopwatch.h"

namespace kinograph::graph {

namespace {
using Clock = std::chrono::steady_clock;
}  // namespace

struct LevenbergMarquardt::Solve {
  Clock::time_point t_start = Clock::now();
  OptimizationResult result;
  double error = 0;  // cost at the current point
  double lambda = 0;
  double nu = 2;           // growth of λ at the next rejection
  double linearize_s = 0;  // of the linearization that started the current iteration
  Eigen::VectorXd D, step, rhs, x_backup;  // sized once the solve iterates
};

struct LevenbergMarquardt::Trial {
  bool factored = false;
  bool step_converged = false;  // the step fell below the step tolerance; nothing was evaluated
  bool accepted = false;
  bool converged = false;        // an accepted step met a cost tolerance
  bool candidate_ready = false;  // candidate_ holds H and g at the trial point
};

LevenbergMarquardt::LevenbergMarquardt(LevenbergMarquardtOptions options) : options_(options) {}
LevenbergMarquardt::~LevenbergMarquardt() = default;
LevenbergMarquardt::LevenbergMarquardt(LevenbergMarquardt&&) noexcept = default;
LevenbergMarquardt& LevenbergMarquardt::operator=(LevenbergMarquardt&&) noexcept = default;

const SparseCholesky* LevenbergMarquardt::cholesky() const {
  return dynamic_cast<const SparseCholesky*>(cholesky_.get());
}

bool LevenbergMarquardt::uses_envelope() const {
  return dynamic_cast<const EnvelopeCholesky*>(cholesky_.get()) != nullptr;
}

void LevenbergMarquardt::set_options(const LevenbergMarquardtOptions& options) {
  if (options.ordering != options_.ordering || options.factorization != options_.factorization ||
      options.threads != options_.threads) {
    equations_.reset();
    candidate_.reset();
    cholesky_.reset();
  }
  options_ = options;
}

OptimizationResult LevenbergMarquardt::optimize(const FactorGraph& graph, Values& values) {
  Solve s;
  throw_if_cancelled();
  prepare(graph, values, s);
  bool ended = start(graph, values, s);
  while (!ended) {
    throw_if_cancelled();  // between trials `values` is the last accepted point
    ended = run_trial(graph, values, s);
  }
  return std::move(s.result);
}

// Rebuilds structure and symbolic analysis when the graph or the layout changed, and the
// candidate equations when trial points are linearized.
void LevenbergMarquardt::prepare(const FactorGraph& graph, const Values& values, Solve& s) {
  const LevenbergMarquardtOptions& o = options_;
  if (!equations_ || !equations_->matches(graph, values)) {
    build_structure(graph, values);
    s.result.symbolic_s = seconds_since(s.t_start);
  }
  if (o.linearize_at_evaluation && (!candidate_ || !candidate_->matches(graph, values))) {
    candidate_ = std::make_unique<NormalEquations>(*equations_);
  }
  if (o.record_history) s.result.history.reserve(std::min(o.max_iterations, 64) * 2);
}

// The pattern of H and its factorization: the envelope in natural order when asked or when it
// wins (kAuto), else CHOLMOD in the options' ordering.
void LevenbergMarquardt::build_structure(const FactorGraph& graph, const Values& values) {
  const LevenbergMarquardtOptions& o = options_;
  cholesky_.reset();
  equations_.reset();
  if (o.factorization == Factorization::kAuto || o.factorization == Factorization::kEnvelope) {
    auto natural = std::make_unique<NormalEquations>(graph, values, OrderingMethod::kNatural,
                                                     o.threads);
    const int n = natural->dim();
    if (n > 0 && (o.factorization == Factorization::kEnvelope ||
                  EnvelopeCholesky::wins(n, natural->col_ptr(), natural->row_idx()))) {
      cholesky_ = std::make_unique<EnvelopeCholesky>(n, natural->col_ptr(), natural->row_idx());
      equations_ = std::move(natural);
      return;
    }
    if (o.ordering == OrderingMethod::kNatural) equations_ = std::move(natural);
  }
  if (!equations_) {
    equations_ = std::make_unique<NormalEquations>(graph, values, o.ordering, o.threads);
  }
  if (equations_->dim() > 0) {
    cholesky_ = std::make_unique<SparseCholesky>(equations_->dim(), equations_->col_ptr(),
                                                 equations_->row_idx(), o.factorization);
  }
}

// Linearizes at the start point, where the solve may already end, and sets up damping.
bool LevenbergMarquardt::start(const FactorGraph& graph, const Values& values, Solve& s) {
  const LevenbergMarquardtOptions& o = options_;
  NormalEquations& eq = *equations_;
  std::string reason;
  const auto t = Clock::now();
  if (!eq.linearize(graph, values, &s.error, &reason)) {
    finish(s, SolverStatus::kNonFinite, reason);
    return true;
  }
  s.linearize_s = seconds_since(t);
  s.result.linearize_s += s.linearize_s;
  s.result.initial_error = s.result.final_error = s.error;
  s.result.iterations = 1;
  if (s.error <= o.absolute_error_tol) {
    finish(s, SolverStatus::kConverged, "error at or below the absolute tolerance");
    return true;
  }
  const int n = eq.dim();
  if (n == 0) {
    finish(s, SolverStatus::kConverged, "no free variables");
    return true;
  }
  s.D.resize(n);
  s.step.resize(n);
  s.rhs.resize(n);
  s.x_backup.resize(values.vector().size());
  update_damping(s);
  s.lambda = o.lambda_initial;
  s.nu = 2;
  return false;
}

// D for the current linearization.
void LevenbergMarquardt::update_damping(Solve& s) const {
  const LevenbergMarquardtOptions& o = options_;
  const NormalEquations& eq = *equations_;
  if (o.damping == Damping::kIdentity) {
    s.D.setOnes();
    return;
  }
  for (int c = 0; c < eq.dim(); ++c) {
    s.D[c] = std::clamp(eq.hessian()[eq.diagonal_positions()[c]], o.min_diagonal, o.max_diagonal);
  }
}

// One trial at the current λ; an iteration is the trials until a step decreases the error.
bool LevenbergMarquardt::run_trial(const FactorGraph& graph, Values& values, Solve& s) {
  IterationStats stats;
  stats.iteration = s.result.iterations - 1;
  stats.linearize_s = s.linearize_s;
  s.linearize_s = 0;
  stats.lambda = s.lambda;
  ++s.result.trials;
  const Trial trial = try_step(graph, values, s, stats);
  if (trial.step_converged) {
    stats.error = s.error;
    if (options_.record_history) s.result.history.push_back(stats);
    s.result.lambda = s.lambda;
    finish(s, SolverStatus::kConverged, "step below the step tolerance");
    return true;
  }
  stats.accepted = trial.accepted;
  record(s, stats);
  s.result.lambda = s.lambda;
  return trial.accepted ? next_iteration(graph, values, s, trial)
                        : increase_lambda(values, s, trial.factored);
}

// Solves (H + λD) δ = −g and tries x + δ; values keep the step only if it is accepted.
LevenbergMarquardt::Trial LevenbergMarquardt::try_step(const FactorGraph& graph, Values& values,
                                                       Solve& s, IterationStats& stats) {
  Trial trial;
  trial.factored = factorize_damped(s, stats);
  if (!trial.factored) return trial;
  const auto t = Clock::now();
  s.rhs = -equations_->gradient();
  cholesky_->solve(s.rhs, s.step);
  stats.solve_s = seconds_since(t);
  throw_if_cancelled();  // the factorization of a long trajectory is a large part of a trial
  s.result.solve_s += stats.solve_s;
  stats.step_norm = s.step.norm();
  const double x_norm = values.vector().norm();
  // A non-finite step is treated like a failed factorization: more damping.
  if (!s.step.allFinite()) return trial;
  if (stats.step_norm <= options_.step_tol * (x_norm + options_.step_tol)) {
    trial.step_converged = true;
    return trial;
  }
  evaluate_step(graph, values, s, stats, trial);
  return trial;
}

// Numeric factorization of H + λD; false if it is not positive definite.
bool LevenbergMarquardt::factorize_damped(Solve& s, IterationStats& stats) {
  const NormalEquations& eq = *equations_;
  const std::vector<double>& h = eq.hessian();
  const std::vector<int>& diag = eq.diagonal_positions();
  const auto t = Clock::now();
  double* A = cholesky_->values();
  std::copy(h.begin(), h.end(), A);
  for (int c = 0; c < eq.dim(); ++c) A[diag[c]] += s.lambda * s.D[c];
  const bool factored = cholesky_->factorize();
  stats.factorize_s = seconds_since(t);
  s.result.factorize_s += stats.factorize_s;
  return factored;
}

// Evaluates the cost at x + δ (with its Jacobians into candidate_ if asked), then keeps the step
// or restores x.
void LevenbergMarquardt::evaluate_step(const FactorGraph& graph, Values& values, Solve& s,
                                       IterationStats& stats, Trial& trial) {
  NormalEquations& eq = *equations_;
  // Model decrease ½(λδᵀDδ − gᵀδ) of the linearized cost for the step δ.
  const double predicted =
      0.5 * (s.lambda * s.step.dot(s.D.asDiagonal() * s.step) - eq.gradient().dot(s.step));
  const auto t = Clock::now();
  s.x_backup = values.vector();
  eq.add_step(s.step, values.vector());
  double new_error = 0;
  bool finite = false;
  try {
    trial.candidate_ready = options_.linearize_at_evaluation &&
                            candidate_->linearize(graph, values, &new_error, nullptr);
    // Without the candidate (or when its Jacobian is not finite) the error alone decides, and a
    // non-finite Jacobian is reported by the linearization after acceptance.
    finite = trial.candidate_ready || eq.evaluate_error(graph, values, &new_error, nullptr);
  } catch (const Cancelled&) {
    values.vector() = s.x_backup;  // a cancelled solve leaves the last accepted point
    throw;
  }
  stats.evaluate_s = seconds_since(t);
  s.result.evaluate_s += stats.evaluate_s;
  stats.error = finite ? new_error : std::numeric_limits<double>::infinity();
  // At the optimum both the model decrease and the actual change sink below the rounding of the
  // cost; such a step is as good as any and is kept, so LM can polish x to full precision
  // instead of mistaking rounding for a failed step.
  const double rounding = 8 * std::numeric_limits<double>::epsilon() * s.error;
  const bool at_rounding = predicted <= rounding && new_error - s.error <= rounding;
  if (finite && (new_error < s.error || at_rounding)) {
    accept_step(s, predicted, new_error, at_rounding, trial);
  } else {
    values.vector() = s.x_backup;
  }
}

// Nielsen's λ update from the ratio of actual to predicted decrease, and the cost tolerances.
void LevenbergMarquardt::accept_step(Solve& s, double predicted, double new_error, bool at_rounding,
                                     Trial& trial) const {
  const LevenbergMarquardtOptions& o = options_;
  trial.accepted = true;
  const double rho = (predicted > 0 && !at_rounding) ? (s.error - new_error) / predicted : 1.0;
  s.lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
  s.lambda = std::max(s.lambda, o.lambda_min);
  s.nu = 2;
  const double relative_decrease = (s.error - new_error) / s.error;
  s.error = new_error;
  s.result.final_error = s.error;
  trial.converged = relative_decrease < o.relative_error_tol || s.error <= o.absolute_error_tol;
}

// Appends the trial to the history and logs it, as the options ask.
void LevenbergMarquardt::record(Solve& s, const IterationStats& stats) const {
  if (options_.record_history) s.result.history.push_back(stats);
  if (options_.log_iterations) {
    spdlog::debug("LM it {} λ={:.3g} |δ|={:.3g} error={:.9g} {}", stats.iteration, stats.lambda,
                  stats.step_norm, stats.error, stats.accepted ? "accepted" : "rejected");
  }
}

// After an accepted step: the convergence and iteration-limit tests, then the linearization
// that starts the next iteration (already done in candidate_ when it is ready).
bool LevenbergMarquardt::next_iteration(const FactorGraph& graph, const Values& values, Solve& s,
                                        const Trial& trial) {
  const LevenbergMarquardtOptions& o = options_;
  if (trial.converged) {
    finish(s, SolverStatus::kConverged,
           s.error <= o.absolute_error_tol ? "error at or below the absolute tolerance"
                                           : "relative decrease below tolerance");
    return true;
  }
  if (s.result.iterations >= o.max_iterations) {
    finish(s, SolverStatus::kMaxIterations,
           "reached " + std::to_string(o.max_iterations) + " iterations");
    return true;
  }
  const auto t = Clock::now();
  std::string reason;
  if (trial.candidate_ready) {
    std::swap(*equations_, *candidate_);
  } else if (!equations_->linearize(graph, values, &s.error, &reason)) {
    finish(s, SolverStatus::kNonFinite, reason);
    return true;
  }
  s.linearize_s = seconds_since(t);
  s.result.linearize_s += s.linearize_s;
  ++s.result.iterations;
  update_damping(s);
  return false;
}

// After a rejected trial: λ grows by ν (2, 4, 8…); past lambda_max the solve gives up.
bool LevenbergMarquardt::increase_lambda(const Values& values, Solve& s, bool factored) const {
  s.lambda *= s.nu;
  s.nu *= 2;
  if (s.lambda > options_.lambda_max) {
    s.result.lambda = s.lambda;
    if (!factored) {
      finish(s, SolverStatus::kSingular,
             "normal equations not positive definite at variable " +
                 equations_->key_of_column(cholesky_->failed_column(), values).to_string() +
                 " even with lambda " + std::to_string(s.lambda / s.nu * 2));
    } else {
      finish(s, SolverStatus::kNoDecrease,
             "no step decreased the error up to lambda " + std::to_string(options_.lambda_max));
    }
    return true;
  }
  return false;
}

// Sets the outcome; the caller returns right after.
void LevenbergMarquardt::finish(Solve& s, SolverStatus status, std::string reason) const {
  OptimizationResult& result = s.result;
  result.status = status;
  result.reason = std::move(reason);
  result.total_s = seconds_since(s.t_start);
  if (options_.log_iterations) {
    spdlog::debug("LM: {} after {} iterations, error {:.6g} -> {:.6g}: {}", to_string(status),
                  result.iterations, result.initial_error, result.final_error, result.reason);
  }
}

}  // namespace kinograph::graph

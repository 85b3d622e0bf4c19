#include "kinograph/planning/plan.h"

#include <algorithm>
#include <ostream>
#include <stdexcept>

namespace kinograph::planning {
namespace {
constexpr PlanStatus kAll[] = {PlanStatus::kConverged,      PlanStatus::kInfeasible,
                               PlanStatus::kNonFinite,      PlanStatus::kSingular,
                               PlanStatus::kMaxUpdates,     PlanStatus::kMaxRounds,
                               PlanStatus::kInvalidProblem, PlanStatus::kNoPlan,
                               PlanStatus::kFailed};
}  // namespace

SolveTimes& SolveTimes::operator+=(const SolveTimes& other) {
  initialization_s += other.initialization_s;
  graph_building_s += other.graph_building_s;
  linearization_s += other.linearization_s;
  factorization_s += other.factorization_s;
  triangular_solve_s += other.triangular_solve_s;
  multipliers_s += other.multipliers_s;
  between_knot_checks_s += other.between_knot_checks_s;
  validation_s += other.validation_s;
  return *this;
}

double SolveTimes::total_s() const {
  return initialization_s + graph_building_s + linearization_s + factorization_s +
         triangular_solve_s + multipliers_s + between_knot_checks_s + validation_s;
}

void add_work(SolveStats& into, const SolveStats& from) {
  into.iterations += from.iterations;
  into.outer_iterations += from.outer_iterations;
  into.linear_solves += from.linear_solves;
  into.times += from.times;
}

std::string to_string(PlanStatus status) {
  switch (status) {
    case PlanStatus::kConverged: return "converged";
    case PlanStatus::kInfeasible: return "infeasible";
    case PlanStatus::kNonFinite: return "non_finite";
    case PlanStatus::kSingular: return "singular";
    case PlanStatus::kMaxUpdates: return "max_updates";
    case PlanStatus::kMaxRounds: return "max_rounds";
    case PlanStatus::kInvalidProblem: return "invalid_problem";
    case PlanStatus::kNoPlan: return "no_plan";
    case PlanStatus::kFailed: return "failed";
  }
  return "failed";
}

PlanStatus plan_status_from_string(const std::string& name) {
  for (PlanStatus s : kAll) {
    if (to_string(s) == name) return s;
  }
  throw std::invalid_argument("unknown plan status '" + name + "'");
}

Plan failed_plan(const std::string& method, PlanStatus status, const std::string& reason) {
  Plan p;
  p.stats.method = method;
  p.stats.status = status;
  p.stats.reason = reason;
  p.validation.valid = false;
  p.validation.failures.push_back(to_string(status) + ": " + reason);
  return p;
}

Plan gone_on(const Plan& plan, int knots) {
  const int rows = static_cast<int>(plan.q.rows());
  if (knots < 0 || knots >= rows) {
    throw std::invalid_argument("gone_on: " + std::to_string(knots) + " knots on a plan of " +
                                std::to_string(rows));
  }
  Plan c = plan;
  c.stats = SolveStats();
  c.validation = Validation();
  for (int k = 0; k < rows; ++k) {
    const int from = std::min(k + knots, rows - 1);
    c.q.row(k) = plan.q.row(from);
    c.qd.row(k) = plan.qd.row(from);
    c.qdd.row(k) = plan.qdd.row(from);
    if (c.tau.rows() == rows) c.tau.row(k) = plan.tau.row(from);
    if (k + knots >= rows) {
      c.qd.row(k).setZero();
      c.qdd.row(k).setZero();
    }
  }
  return c;
}

std::ostream& operator<<(std::ostream& os, PlanStatus status) { return os << to_string(status); }

}  // namespace kinograph::planning

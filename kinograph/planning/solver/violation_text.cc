#include "kinograph/planning/solver/violation_text.h"

#include <iterator>
#include <sstream>

#include "kinograph/planning/user_terms.h"

namespace kinograph::planning {
namespace {

// The user's name of each role, in FactorRole's declaration order.
constexpr const char* kRoleNames[] = {"start",
                                      "goal",
                                      "smoothness prior",
                                      "collocation",
                                      "dynamics between the knots",
                                      "limits",
                                      "equations of motion",
                                      "collision",
                                      "task constraint",
                                      "self-collision"};
static_assert(std::size(kRoleNames) == static_cast<size_t>(FactorRole::kSelfCollision) + 1,
              "one name per role: a new role needs its name here");

const char* role_name(FactorRole role) {
  const auto i = static_cast<size_t>(role);
  return i < std::size(kRoleNames) ? kRoleNames[i] : "constraint";
}

}  // namespace

std::string describe_violation(const Problem& problem, const ConstraintReport& worst) {
  if (worst.entry == nullptr || worst.row < 0 || !worst.entry->constrained || !problem.model) {
    return worst.where.empty() ? "all constraints hold" : worst.where;
  }
  const FactorEntry& e = *worst.entry;
  const double dt = problem.dt(), t = e.key.step * dt;
  ConstrainedFactor::RowContext context{*problem.model, t, dt, role_name(e.key.role),
                                        e.key.role == FactorRole::kTask ? e.key.index : -1,
                                        worst.violation};
  const std::string text = e.constrained->describe_row(worst.row, worst.value, context);
  if (!text.empty()) return text;
  // The DFG's equations: the role and time, with the factor for the specialist.
  return std::string(role_name(e.key.role)) + " at " + at_time(t) + " off by " +
         number(worst.violation) + " (" + worst.where + ")";
}

std::string infeasible_reason(const Problem& problem, const OuterLoopResult& result) {
  std::ostringstream os;
  os << "constraints still violated after " << result.outer_iterations << " outer and "
     << result.iterations
     << " LM iterations; the worst: " << describe_violation(problem, result.worst);
  return os.str();
}

}  // namespace kinograph::planning

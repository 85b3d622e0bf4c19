#include "kinograph/planning/incremental/stopping_rule.h"

#include <algorithm>

namespace kinograph::planning {
namespace {
// Relative error decrease that settles the first round, tightened 10× per round down to the
// final one (the batch planner's inner solves tighten the same way).
constexpr double kInitialRelativeDecrease = 1e-2;
constexpr double kFinalRelativeDecrease = 1e-4;
// Accept a valid plan whose objective fell by less than this fraction, or rose by less than
// the next, since the previous update.
constexpr double kObjectiveFall = 5e-2;
constexpr double kObjectiveRise = 0.5;
}  // namespace

StoppingRule::StoppingRule(double constraint_tolerance, double previous_cost,
                           bool stop_at_first_valid)
    : tolerance_(constraint_tolerance),
      last_cost_(previous_cost),
      stop_at_first_valid_(stop_at_first_valid),
      round_tolerance_(kInitialRelativeDecrease) {}

namespace {
// Whether `cost` is within the band of `ref`.
bool within_band(double cost, double ref) {
  ref = std::max(ref, 1e-12);
  return cost >= (1 - kObjectiveFall) * ref && cost <= (1 + kObjectiveRise) * ref;
}
}  // namespace

bool StoppingRule::accept(double cost) {
  if (!stop_at_first_valid_) return false;
  const bool settled =
      within_band(cost, last_cost_) || (before_jump_ >= 0 && within_band(cost, before_jump_));
  if (cost > (1 + kObjectiveRise) * std::max(last_cost_, 1e-12)) {
    if (before_jump_ < 0) before_jump_ = last_cost_;
  } else {
    before_jump_ = -1;
  }
  last_cost_ = cost;
  return settled;
}

bool StoppingRule::settled(double error_before, double error_after) const {
  return error_before - error_after <= round_tolerance_ * std::max(error_before, 1e-12);
}

StoppingRule::Next StoppingRule::after_settling(double worst_violation) {
  if (worst_violation <= tolerance_ && round_tolerance_ > kFinalRelativeDecrease) {
    round_tolerance_ = kFinalRelativeDecrease;
    return Next::kSettleObjective;
  }
  if (worst_violation <= tolerance_) return Next::kPolish;
  round_tolerance_ = std::max(kFinalRelativeDecrease, 0.1 * round_tolerance_);
  return Next::kMultiplierRound;
}

}  // namespace kinograph::planning

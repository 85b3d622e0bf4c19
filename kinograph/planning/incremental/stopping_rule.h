#pragma once
// When a replan's ISAM2 updates stop. Each update is a safeguarded Gauss–Newton step; at one
// multiplier estimate the updates "settle" when one lowers the error by little. Then a
// multiplier round runs while constraints are violated; once they hold, the objective is
// settled at a tighter tolerance and one polishing update ends the replan.
namespace kinograph::planning {

/// The stopping rule of one replan, with its state (tolerance reached, previous objective).
class StoppingRule {
 public:
  /// `constraint_tolerance`: the scaled violation every row must meet; `previous_cost`: the
  /// objective of the plan before the change; `stop_at_first_valid`: see accept().
  StoppingRule(double constraint_tolerance, double previous_cost, bool stop_at_first_valid);

  /// Whether an update's objective (soft cost) is settled enough that its plan, if it
  /// validates, is the answer: it fell by less than 5 % (a plan whose objective still falls is
  /// not yet the optimum, e.g. after an obstacle was removed) and rose by less than 50 % (a
  /// jump is a poor first iterate after a large goal change) since the previous update. After
  /// a jump the objective is also settled within the same band of the last one before the
  /// jump: a jump is a poor iterate, no measure of whether the objective still falls. Always
  /// false unless stop_at_first_valid. Remembers `cost` for the next update.
  bool accept(double cost);
  /// Whether the updates settled at this multiplier estimate (relative decrease below the
  /// round's tolerance, which tightens with every round like the batch's inner solves).
  bool settled(double error_before, double error_after) const;

  /// What to do once settled, given the worst scaled constraint violation.
  enum class Next {
    kSettleObjective,  ///< feasible: keep sweeping at the final tolerance
    kPolish,           ///< feasible and settled: one update relinearizing everything, then stop
    kMultiplierRound,  ///< violated: update multipliers, tighten the tolerance
  };
  Next after_settling(double worst_violation);

  /// Whether a multiplier round's change of a row (scaled) or its violation is too small to
  /// re-add the factor: half the constraint tolerance.
  bool negligible(double scaled) const { return scaled <= 0.5 * tolerance_; }

 private:
  double tolerance_;
  double last_cost_;
  double before_jump_ = -1;  // the objective before the jumps that led to last_cost_, if any
  bool stop_at_first_valid_;
  double round_tolerance_;
};

}  // namespace kinograph::planning

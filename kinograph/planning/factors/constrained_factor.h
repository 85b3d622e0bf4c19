#pragma once
// A factor whose rows are soft terms or must-hold constraints. Constraint rows enter the cost
// through an augmented Lagrangian whose multipliers and penalty μ are not the factor's own: they
// live in a Multipliers record beside it (owned by a solver's ConstraintState), which the factor
// only reads. The outer loop changes them between solves without touching the graph's structure.
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "kinograph/graph/factor.h"
#include "kinograph/graph/values.h"

namespace kinograph::dynamics {
class Model;
}

namespace kinograph::planning {

/// How one row z_i of a ConstrainedFactor enters the cost.
enum class RowKind {
  kSoft,      ///< weight·(z − lower), a plain least-squares term
  kEquality,  ///< z = lower, enforced by the augmented Lagrangian
  kBounds,    ///< lower ≤ z ≤ upper (either may be ±inf), augmented Lagrangian (the hinge)
};

/// One row: its kind, target/bounds, and its scale s (constraint rows are measured as z/s, so
/// that one penalty μ suits rows of different units; soft rows use `weight` instead).
struct RowSpec {
  RowKind kind = RowKind::kEquality;
  double lower = 0;   ///< target of soft and equality rows; lower bound of kBounds
  double upper = 0;   ///< upper bound of kBounds
  double scale = 1;   ///< s > 0 of constraint rows
  double weight = 1;  ///< soft rows: r = weight·(z − lower)
};

/// The augmented-Lagrangian state of one factor's rows: penalty μ and per-row multipliers.
struct Multipliers {
  explicit Multipliers(int rows = 0, double penalty = 1);
  double penalty = 1;     ///< μ > 0
  Eigen::VectorXd lower;  ///< λ of equality rows, λ_l ≥ 0 of lower bounds
  Eigen::VectorXd upper;  ///< λ_u ≥ 0 of upper bounds
};

/// Base of the planner's factors. Subclasses compute the raw values z (one per row) and dz/dx;
/// this class turns them into whitened residuals:
///   soft:      r = w (z − t)
///   equality:  r = √μ c + λ/√μ,                      c = (z − t)/s
///   bounds:    r = max(0, √μ c_l + λ_l/√μ) − max(0, √μ c_u + λ_u/√μ),
///              c_l = (lower − z)/s ≤ 0,  c_u = (z − upper)/s ≤ 0,
/// so ½r² is the augmented-Lagrangian term of the row (up to a constant); μ and λ come from the
/// bound Multipliers.
class ConstrainedFactor : public graph::Factor {
 public:
  /// Throws std::invalid_argument on empty rows, non-positive scales or crossed bounds.
  ConstrainedFactor(std::vector<graph::Key> keys, std::vector<int> dims, std::vector<RowSpec> rows);

  /// Raw values z (residual_dim rows) and, if J is non-null, dz/dx (blocks zeroed on entry).
  virtual void compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
                       const graph::Jacobians* J) const = 0;

  void evaluate(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const graph::Jacobians* J) const final;
  bool writes_listed_rows_only() const override { return lists_written_rows_; }

  const std::vector<RowSpec>& rows() const { return rows_; }

  /// What describe_row needs besides the factor: the robot, the time and purpose of the row.
  struct RowContext {
    const dynamics::Model& model;
    double t = 0;                  ///< time of the factor's state (s)
    double dt = 0;                 ///< time between states (s)
    const char* role = "";         ///< the row's purpose ("goal", "start", "task constraint", …)
    int index = -1;                ///< which task constraint (0-based); −1 for other rows
    double violation = 0;          ///< how far the row is past its bound, in its own units
  };
  /// Row `row` with raw value z in the user's terms (joint, link, obstacle, time, amount);
  /// empty when the factor knows nothing better to say than its role and time.
  virtual std::string describe_row(int /*row*/, double /*z*/, const RowContext& /*c*/) const {
    return "";
  }
  /// Whether any row is a constraint (so the augmented Lagrangian must track this factor).
  bool has_constraints() const { return num_constraints_ > 0; }
  /// Whether any row is soft (part of the objective).
  bool has_soft_rows() const { return num_constraints_ < residual_dim(); }

  /// Reads μ and the multipliers from `m` from now on (an unbound factor reads μ = 1, λ = 0).
  /// Marks the Jacobian changed when μ differs from the one read so far. Throws
  /// std::invalid_argument if m is null, its sizes are not residual_dim or μ ≤ 0.
  void bind(std::shared_ptr<const Multipliers> m);
  /// Call after changing the bound record's penalty in place (marks the Jacobian changed).
  void penalty_changed();

  /// Raw values z at `values` (for reports and multiplier updates).
  void values_at(const graph::Values& values, Eigen::VectorXd& z) const;
  /// The same into a preallocated z (residual_dim rows); allocates nothing.
  void compute_at(const graph::Values& values, Eigen::Ref<Eigen::VectorXd> z) const;

  /// The worst constraint row at some values: its violation scaled (|c| = violation / s) and in
  /// its own units.
  struct Violation {
    double scaled = 0;
    double own_units = 0;
    int row = -1;      ///< the worst constraint row, −1 when every row holds
    double value = 0;  ///< its raw value z
  };
  /// The worst constraint row at `values` (one evaluation, no allocation).
  Violation check(const graph::Values& values) const;
  /// Largest constraint violation in the rows' own units (|z − t| or the bound excess).
  double violation(const graph::Values& values) const;
  /// The soft rows' cost ½Σ(w(z − t))² and violation(), from one evaluation.
  struct Terms {
    double soft_cost = 0;
    double violation = 0;
  };
  Terms terms(const graph::Values& values) const;
  /// Largest violation measured in scaled units (|c| = violation / s).
  double scaled_violation(const graph::Values& values) const;
  /// First-order multiplier update λ ← λ + μc of `m` (bounds clipped ≥ 0, μ = m.penalty) at
  /// `values`; returns the worst row before the update, from the same evaluation.
  Violation update_multipliers(const graph::Values& values, Multipliers& m) const;

 protected:
  /// Whether compute() must fill row `row`'s Jacobian for raw value z: false only while
  /// evaluate() runs and the row is a bound whose hinge is off under the bound multipliers
  /// (its residual and Jacobian row are then zero whatever compute() writes).
  bool jacobian_row_needed(int row, double z) const;
  /// Whether every multiplier is zero (so is an unbound factor's): a bound row's hinge is then
  /// off exactly where its value lies within its bounds.
  bool bound_multipliers_zero() const;
  /// For compute() of a factor whose rows are all bounds, once it has found every value it
  /// wrote strictly within its bounds and bound_multipliers_zero(): every hinge is then off, and
  /// evaluate() zeroes the residual and lists no Jacobian row without testing each row. Has no
  /// effect outside evaluate().
  void rows_proven_clear() const;
  /// For compute() without Jacobians, when bound_multipliers_zero(): it measured only the rows
  /// at or past a bound and wrote some value within the bounds for the others (their hinges are
  /// off whatever the value). The kept values are then read again only while every multiplier
  /// stays zero. Called in an evaluation with Jacobians, it throws std::logic_error.
  void clear_rows_not_measured() const;
  /// For a subclass whose compute() is linear in the variables: with soft and equality rows only
  /// the whitened Jacobian is then constant between penalty changes (Factor::jacobian_version).
  /// Throws std::logic_error if a row is a bound.
  void declare_linear();
  /// For a subclass whose compute() is expensive (the dynamics rows): the last evaluation with
  /// and the last without Jacobians are kept and reused while the variables are bitwise the
  /// same, so results are those of compute(). The outer loop linearizes at the point LM stopped
  /// at twice (its last trial, the next solve's start); only the multipliers differ between.
  /// Values alone (compute_at) are read from either, so a cost or violation read at the point
  /// just linearized costs no evaluation.
  void cache_evaluations();
  /// For a subclass whose compute() is expensive and whose Jacobian is too large to keep (the
  /// collision rows): only the last values are kept, from either kind of evaluation, and read
  /// again while the variables are bitwise the same (cost, violation and multiplier updates at
  /// the point just linearized). Not with cache_evaluations().
  void cache_values();
  /// For a subclass whose Jacobian is mostly rows of clear pairs (the collision rows): given a
  /// row list (graph::Jacobians::row_support()), compute() appends to it every row whose
  /// Jacobian it writes, and writes those rows in full (every block). J then arrives unzeroed
  /// (Factor::writes_listed_rows_only); evaluate() zeroes the rows it lists that compute() did
  /// not write. Not with cache_evaluations().
  void list_written_rows();

 private:
  // A kept raw evaluation: inputs (keys concatenated), z and, in the one with Jacobians,
  // dz/dx with the rows compute() filled (an inactive bound's row may be left unfilled).
  struct Evaluation {
    Eigen::VectorXd x, z;
    Eigen::MatrixXd J;
    std::vector<char> filled;
    bool valid = false;
    bool clear_rows_not_measured = false;  // see clear_rows_not_measured()
  };
  // compute(), or the kept evaluation when it is at the same x and has every Jacobian row
  // needed now (called while this factor is evaluating, so inactive rows are known).
  void cached_compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
                      const graph::Jacobians* J) const;
  // Records x and z as `k`'s evaluation.
  void keep(Evaluation& k, const graph::FactorValues& x,
            const Eigen::Ref<const Eigen::VectorXd>& z) const;
  // Whether `k` was evaluated at x and its values serve now (clear rows measured, or every
  // multiplier zero).
  bool kept_at(const Evaluation& k, const graph::FactorValues& x) const;
  // Whether the kept evaluation is at x (and has the Jacobian rows needed now, if asked).
  bool reusable(const graph::FactorValues& x, bool with_jacobian) const;

  // check() and, with non-null multipliers, their update from the same evaluation.
  Violation scan(const graph::Values& values, Multipliers* update) const;

  std::vector<RowSpec> rows_;
  int num_constraints_ = 0;
  bool lists_written_rows_ = false;
  std::shared_ptr<const Multipliers> m_;  // null until bound
  double penalty_read_ = 1;               // μ of the last bind or penalty_changed
  // Empty unless cached: cache_values() keeps the last values; cache_evaluations() the last
  // evaluation without, then with, Jacobians.
  mutable std::vector<Evaluation> kept_;
};

}  // namespace kinograph::planning

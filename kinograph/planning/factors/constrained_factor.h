#pragma once
// A factor whose rows are soft terms or must-hold constraints. Constraint rows enter the cost
// through an augmented Lagrangian: the factor holds each row's multipliers and the penalty μ, so
// the outer loop changes them between LM solves without touching the graph's structure (the
// solver keeps its symbolic analysis).
#include <Eigen/Core>
#include <vector>

#include "kinograph/graph/factor.h"
#include "kinograph/graph/values.h"

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

/// Base of the planner's factors. Subclasses compute the raw values z (one per row) and dz/dx;
/// this class turns them into whitened residuals:
///   soft:      r = w (z − t)
///   equality:  r = √μ c + λ/√μ,                      c = (z − t)/s
///   bounds:    r = max(0, √μ c_l + λ_l/√μ) − max(0, √μ c_u + λ_u/√μ),
///              c_l = (lower − z)/s ≤ 0,  c_u = (z − upper)/s ≤ 0,
/// so ½r² is the augmented-Lagrangian term of the row (up to a constant).
class ConstrainedFactor : public graph::Factor {
 public:
  /// Throws std::invalid_argument on empty rows, non-positive scales or crossed bounds.
  ConstrainedFactor(std::vector<graph::Key> keys, std::vector<int> dims, std::vector<RowSpec> rows);

  /// Raw values z (residual_dim rows) and, if J is non-null, dz/dx (blocks zeroed on entry).
  virtual void compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
                       const graph::Jacobians* J) const = 0;

  void evaluate(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const graph::Jacobians* J) const final;

  const std::vector<RowSpec>& rows() const { return rows_; }
  /// Whether any row is a constraint (so the augmented Lagrangian must track this factor).
  bool has_constraints() const { return num_constraints_ > 0; }
  /// Whether any row is soft (part of the objective).
  bool has_soft_rows() const { return num_constraints_ < residual_dim(); }

  /// Penalty μ of the constraint rows.
  double penalty() const { return mu_; }
  void set_penalty(double mu);
  /// Multipliers: of equality rows (λ) and of lower/upper bounds (λ_l, λ_u ≥ 0) per row.
  const Eigen::VectorXd& multipliers() const { return lambda_; }
  const Eigen::VectorXd& multipliers_upper() const { return lambda_upper_; }
  void set_multipliers(const Eigen::VectorXd& lambda, const Eigen::VectorXd& lambda_upper);
  void reset_multipliers();

  /// Raw values z at `values` (for reports and multiplier updates).
  void values_at(const graph::Values& values, Eigen::VectorXd& z) const;
  /// The same into a preallocated z (residual_dim rows); allocates nothing.
  void compute_at(const graph::Values& values, Eigen::Ref<Eigen::VectorXd> z) const;

  /// The worst constraint row at some values: its violation scaled (|c| = violation / s) and in
  /// its own units.
  struct Violation {
    double scaled = 0;
    double own_units = 0;
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
  /// First-order multiplier update λ ← λ + μc (bounds clipped ≥ 0) at `values`; returns the
  /// worst row before the update, from the same evaluation.
  Violation update_multipliers(const graph::Values& values);

 protected:
  /// For a subclass whose compute() is linear in the variables: with soft and equality rows only
  /// the whitened Jacobian is then constant between penalty changes (Factor::jacobian_version).
  /// Throws std::logic_error if a row is a bound.
  void declare_linear();

 private:
  // check() and, with non-null multipliers, their update from the same evaluation.
  Violation scan(const graph::Values& values, Eigen::VectorXd* lambda,
                 Eigen::VectorXd* lambda_upper) const;

  std::vector<RowSpec> rows_;
  int num_constraints_ = 0;
  double mu_ = 1.0;
  Eigen::VectorXd lambda_, lambda_upper_;
};

}  // namespace kinograph::planning

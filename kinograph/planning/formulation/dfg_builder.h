#pragma once
// Adds one time step of the dynamic factor graph (twist, acceleration, wrench and torque factors
// of every body, with their V, V̇, F, τ variables) to a graph, initialised from RNEA so that the
// solver starts at zero dynamics residual.
#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/graph/factor_graph.h"
#include "kinograph/graph/values.h"
#include "kinograph/planning/factors/constrained_factor.h"
#include "kinograph/planning/factors/dfg_factors.h"
#include "kinograph/planning/factors/dynamics_factors.h"
#include "kinograph/planning/formulation/planning_graph.h"
#include "kinograph/planning/problem.h"

namespace kinograph::planning {

/// How the DFG names its variables at a step k. Joint quantities are components of the
/// planner's joint vectors q(0,k), v(0,k), a(0,k) (dimension nq) by default; the DFG's own
/// variables are per body: twist V(i,k), acceleration A(i,k), wrench F(i,k) (6-vectors), and
/// torque T(i,k) (a scalar) or, with torque_vector, one nq-vector T(0,k).
struct DfgKeys {
  char q = 'q';                ///< joint angles, one nq-vector per step (index 0)
  char qd = 'v';               ///< joint velocities, one nq-vector per step
  char qdd = 'a';              ///< joint accelerations, one nq-vector per step
  char twist = 'V';            ///< body twist V_i, 6-vector, index = body
  char accel = 'A';            ///< body twist acceleration V̇_i, 6-vector, index = body
  char wrench = 'F';           ///< joint wrench F_i (parent on body i, body i's frame), 6-vector
  char torque = 'T';           ///< joint torque τ_i
  bool torque_vector = false;  ///< false: scalars T(i,k); true: one nq-vector T(0,k)

  graph::Key q_key(int step) const { return {q, 0, static_cast<uint32_t>(step)}; }
  graph::Key qd_key(int step) const { return {qd, 0, static_cast<uint32_t>(step)}; }
  graph::Key qdd_key(int step) const { return {qdd, 0, static_cast<uint32_t>(step)}; }
  graph::Key twist_key(int body, int step) const { return key(twist, body, step); }
  graph::Key accel_key(int body, int step) const { return key(accel, body, step); }
  graph::Key wrench_key(int body, int step) const { return key(wrench, body, step); }
  /// The variable holding τ (all joints if torque_vector, else joint `body`'s alone).
  graph::Key torque_key(int body, int step) const {
    return key(torque, torque_vector ? 0 : body, step);
  }
  /// τ_body as a JointScalar of a model with nq joints.
  JointScalar torque_scalar(int body, int step, int nq) const {
    return torque_vector ? JointScalar{torque_key(body, step), nq, body}
                         : JointScalar{torque_key(body, step), 1, 0};
  }

 private:
  static graph::Key key(char kind, int index, int step) {
    return {kind, static_cast<uint32_t>(index), static_cast<uint32_t>(step)};
  }
};

/// Options of the DFG builder.
struct DfgOptions {
  DfgKeys keys;
  /// σ of the isotropic noise of every DFG factor (N·m, rad/s … mixed units: these residuals
  /// are meant to hold, so a constraint method typically replaces the noise models).
  double sigma = 1e-3;
  /// Constant wrenches the environment applies to bodies (body frame, as dynamics::rnea), e.g.
  /// a payload not merged into the Model; they enter the wrench-balance factors.
  std::vector<dynamics::ExternalWrench> external;
  /// Scale s of the equation rows when the DFG is added as augmented-Lagrangian constraints
  /// (add_dfg_constraints): a row's violation is measured as |e|/s.
  double constraint_scale = 1.0;
};

/// Where one step's DFG factors sit in the graph (FactorGraph indices), by kind and body, so a
/// planner can re-weight them, treat them as constraints, or remove them.
struct DfgStep {
  int step = 0;
  std::vector<size_t> twist, accel, wrench, torque;  ///< one per body, in body order

  /// All factor indices of the step (twist, accel, wrench, torque order).
  std::vector<size_t> all() const;
  /// Number of factors (4 per body).
  size_t size() const { return twist.size() + accel.size() + wrench.size() + torque.size(); }
};

/// Adds the 4·nq DFG factors of `step` (variables must be inserted separately, e.g. by
/// set_dfg_values). Throws std::invalid_argument for an external wrench on a missing body.
DfgStep add_dfg_factors(graph::FactorGraph& graph, const dynamics::Model& model, int step,
                        const DfgOptions& options = {});

/// Inserts (or, if present, overwrites) the V, V̇, F, τ variables of `step` with RNEA's values
/// at (q, q̇, q̈), which satisfy every DFG factor of the step exactly. `data` is a workspace.
void set_dfg_values(graph::Values& values, const dynamics::Model& model, dynamics::Data& data,
                    int step, const dynamics::VectorRef& q, const dynamics::VectorRef& qd,
                    const dynamics::VectorRef& qdd, const DfgOptions& options = {});

/// add_dfg_factors plus set_dfg_values, reading q, q̇, q̈ of `step` from `values` (which must
/// hold the joint vectors named by options.keys; std::out_of_range otherwise).
DfgStep add_dfg_dynamics(graph::FactorGraph& graph, graph::Values& values,
                         const dynamics::Model& model, int step, const DfgOptions& options = {});

/// Largest absolute raw residual |e| over the given DFG factors at `values` (0 for none): how far
/// the graph's V, V̇, F, τ are from satisfying the equations of motion.
double dfg_max_residual(const graph::FactorGraph& graph, const graph::Values& values,
                        const std::vector<size_t>& factors);

/// A DFG factor as must-hold equality rows e = 0 (scale s) of the augmented-Lagrangian planner;
/// the wrapped factor's own noise model is ignored.
class DfgConstraintFactor final : public ConstrainedFactor {
 public:
  /// Throws std::invalid_argument on a null factor or a non-positive scale.
  DfgConstraintFactor(graph::FactorPtr equation, double scale);
  void compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
               const graph::Jacobians* J) const override;
  std::string name() const override;
  bool parallel_safe() const override { return equation_->parallel_safe(); }
  const graph::FactorPtr& equation() const { return equation_; }

 private:
  graph::FactorPtr equation_;
};

/// The torque rows of the condensed DynamicsStepFactor (unactuated τ_j = 0, effort bounds,
/// minimum-torque soft rows; same RowSpecs), but on the DFG's torque variables, so the two
/// formulations pose the same problem.
class DfgTorqueRowsFactor final : public ConstrainedFactor {
 public:
  /// Throws std::invalid_argument if the model and options give no rows (see
  /// DynamicsStepFactor::rows_for).
  DfgTorqueRowsFactor(const dynamics::Model& model, int step, const DynamicsStepOptions& options,
                      const DfgKeys& keys = {});
  void compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
               const graph::Jacobians* J) const override;
  bool parallel_safe() const override { return true; }  // touches only its own state
  std::string describe_row(int row, double z, const RowContext& c) const override;

 private:
  std::vector<int> slot_of_row_, comp_of_row_;
};

/// One step of the DFG in the planner's constrained form: what add_dfg_constraints added.
struct DfgConstraintStep {
  int step = 0;
  /// The 4·nq equations of motion (DfgConstraintFactor), then the torque rows if any.
  std::vector<std::shared_ptr<ConstrainedFactor>> factors;
  std::vector<size_t> indices;  ///< their FactorGraph indices, same order
};

/// The DFG formulation of one step for the augmented-Lagrangian planner, in place of the
/// condensed DynamicsStepFactor: adds the equations of motion as equality constraints (scale
/// options.constraint_scale) and the torque rows `torque_rows` on τ, and inserts the step's V, V̇,
/// F, τ initialised by RNEA from q, q̇, q̈ in `values` (std::out_of_range if those are missing).
/// Register every returned factor with the AugmentedLagrangian.
DfgConstraintStep add_dfg_constraints(graph::FactorGraph& graph, graph::Values& values,
                                      const dynamics::Model& model, dynamics::Data& data, int step,
                                      const DynamicsStepOptions& torque_rows,
                                      const DfgOptions& options = {});

/// Switches a planning graph built by build_graph (condensed formulation) to the full DFG: every
/// DynamicsStepFactor is removed from the graph and from pg.constraints, and its step gets the
/// DFG (add_dfg_constraints) with the same torque rows, built from problem.objectives and
/// graph_options exactly as build_graph builds them. Variables are initialised by RNEA from the
/// graph's current q, q̇, q̈. Returns the added steps (empty if the graph had no dynamics rows).
std::vector<DfgConstraintStep> use_dfg_dynamics(PlanningGraph& pg, const Problem& problem,
                                                const GraphOptions& graph_options = {},
                                                const DfgOptions& options = {});

/// The plan of a solved graph's values: states, step times, and τ from inverse dynamics
/// (exact for the condensed formulation, which eliminates τ) except at the steps that hold the
/// DFG's own τ variables (named by `keys`), whose torques are read back so that the validator
/// checks the DFG's equations of motion. Stats and validation are left empty.
Plan plan_from_values(const Problem& problem, const graph::Values& values,
                      const DfgKeys& keys = {});
/// Overwrites plan.tau at the steps whose DFG τ variables `values` holds with those torques.
void read_dfg_torques(Plan& plan, const graph::Values& values, const dynamics::Model& model,
                      const DfgKeys& keys = {});

/// The torques of `step` read back from the graph (nq entries).
Eigen::VectorXd dfg_torques(const graph::Values& values, const dynamics::Model& model, int step,
                            const DfgKeys& keys = {});

}  // namespace kinograph::planning

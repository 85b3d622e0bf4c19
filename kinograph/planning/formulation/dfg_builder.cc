#include "kinograph/planning/formulation/dfg_builder.h"

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>

#include "kinograph/dynamics/data.h"
#include "kinograph/graph/noise_model.h"
#include "kinograph/planning/user_terms.h"

namespace kinograph::planning {

std::vector<size_t> DfgStep::all() const {
  std::vector<size_t> out;
  out.reserve(size());
  for (const auto* v : {&twist, &accel, &wrench, &torque})
    out.insert(out.end(), v->begin(), v->end());
  return out;
}

namespace {

// The 4 factors of every body of one step, by kind, each with noise model `noise6`/`noise1`
// (null = raw error).
struct StepFactors {
  std::vector<graph::FactorPtr> twist, accel, wrench, torque;
};

StepFactors make_step_factors(const dynamics::Model& model, int step, const DfgOptions& options,
                              const graph::NoiseModelPtr& noise6,
                              const graph::NoiseModelPtr& noise1) {
  const int n = model.nq();
  const DfgKeys& k = options.keys;
  std::vector<dynamics::Vector6> external(n, dynamics::Vector6::Zero());
  for (const dynamics::ExternalWrench& w : options.external) {
    if (w.body < 0 || w.body >= n) {
      throw std::invalid_argument("DFG: external wrench on body " + std::to_string(w.body) +
                                  " of a model with " + std::to_string(n) + " bodies");
    }
    external[w.body] += w.wrench;
  }
  auto joint = [&](graph::Key key, int j) { return JointScalar{key, n, j}; };
  const graph::Key q = k.q_key(step), qd = k.qd_key(step), qdd = k.qdd_key(step);
  StepFactors out;
  for (int i = 0; i < n; ++i) {
    const int p = model.bodies[i].parent;
    // For a body on the base the parent keys are ignored by the factors; pass its own.
    const int pk = p >= 0 ? p : i;
    out.twist.push_back(std::make_shared<DfgTwistFactor>(
        model, i, k.twist_key(i, step), k.twist_key(pk, step), joint(q, i), joint(qd, i), noise6));
    out.accel.push_back(std::make_shared<DfgAccelFactor>(
        model, i, k.accel_key(i, step), k.accel_key(pk, step), k.twist_key(i, step), joint(q, i),
        joint(qd, i), joint(qdd, i), noise6));
    std::vector<DfgChild> children;
    for (int c = i + 1; c < n; ++c) {
      if (model.bodies[c].parent == i) children.push_back({c, k.wrench_key(c, step), joint(q, c)});
    }
    out.wrench.push_back(std::make_shared<DfgWrenchFactor>(
        model, i, k.wrench_key(i, step), k.accel_key(i, step), k.twist_key(i, step),
        std::move(children), external[i], noise6));
    out.torque.push_back(std::make_shared<DfgTorqueFactor>(
        model, i, k.torque_scalar(i, step, n), k.wrench_key(i, step), joint(qd, i), noise1));
  }
  return out;
}

}  // namespace

DfgStep add_dfg_factors(graph::FactorGraph& graph, const dynamics::Model& model, int step,
                        const DfgOptions& options) {
  const StepFactors f = make_step_factors(model, step, options, graph::isotropic(6, options.sigma),
                                          graph::isotropic(1, options.sigma));
  DfgStep out;
  out.step = step;
  for (const auto& x : f.twist) out.twist.push_back(graph.add(x));
  for (const auto& x : f.accel) out.accel.push_back(graph.add(x));
  for (const auto& x : f.wrench) out.wrench.push_back(graph.add(x));
  for (const auto& x : f.torque) out.torque.push_back(graph.add(x));
  return out;
}

void set_dfg_values(graph::Values& values, const dynamics::Model& model, dynamics::Data& data,
                    int step, const dynamics::VectorRef& q, const dynamics::VectorRef& qd,
                    const dynamics::VectorRef& qdd, const DfgOptions& options) {
  const int n = model.nq();
  const DfgKeys& k = options.keys;
  dynamics::rnea(model, data, q, qd, qdd, options.external);
  auto put = [&values](graph::Key key, const Eigen::Ref<const Eigen::VectorXd>& v) {
    if (values.contains(key)) {
      values.update(key, v);
    } else {
      values.insert(key, v);
    }
  };
  for (int i = 0; i < n; ++i) {
    put(k.twist_key(i, step), data.V[i]);
    put(k.accel_key(i, step), data.Vdot[i]);
    put(k.wrench_key(i, step), data.F[i]);
    if (!k.torque_vector) put(k.torque_key(i, step), data.tau.segment(i, 1));
  }
  if (k.torque_vector) put(k.torque_key(0, step), data.tau);
}

DfgStep add_dfg_dynamics(graph::FactorGraph& graph, graph::Values& values,
                         const dynamics::Model& model, int step, const DfgOptions& options) {
  const DfgKeys& k = options.keys;
  const Eigen::VectorXd q = values.at(k.q_key(step));
  const Eigen::VectorXd qd = values.at(k.qd_key(step));
  const Eigen::VectorXd qdd = values.at(k.qdd_key(step));
  dynamics::Data data(model);
  set_dfg_values(values, model, data, step, q, qd, qdd, options);
  return add_dfg_factors(graph, model, step, options);
}

double dfg_max_residual(const graph::FactorGraph& graph, const graph::Values& values,
                        const std::vector<size_t>& factors) {
  double worst = 0;
  std::vector<const double*> ptrs;
  Eigen::VectorXd e;
  for (size_t index : factors) {
    const graph::FactorPtr& f = graph.at(index);
    if (!f) continue;
    ptrs.clear();
    for (graph::Key key : f->keys()) ptrs.push_back(values.at(key).data());
    e.setZero(f->residual_dim());
    f->evaluate(graph::FactorValues(ptrs.data(), f->dims().data()), e, nullptr);
    worst = std::max(worst, e.cwiseAbs().maxCoeff());
  }
  return worst;
}

// ---------------------------------------------------------------------------------------------
namespace {

std::vector<RowSpec> equality_rows(const graph::FactorPtr& f, double scale) {
  if (!f) throw std::invalid_argument("DfgConstraintFactor: null factor");
  if (!(scale > 0)) throw std::invalid_argument("DfgConstraintFactor: scale must be positive");
  RowSpec row;
  row.kind = RowKind::kEquality;
  row.lower = 0;
  row.scale = scale;
  return std::vector<RowSpec>(f->residual_dim(), row);
}

std::vector<RowSpec> torque_rows_checked(const dynamics::Model& model,
                                         const DynamicsStepOptions& options) {
  std::vector<RowSpec> rows = DynamicsStepFactor::rows_for(model, options);
  if (rows.empty()) throw std::invalid_argument("DfgTorqueRowsFactor: the model has no rows");
  return rows;
}

// The torque variables the rows read, merged when τ is one vector.
detail::DfgLayout torque_rows_layout(const dynamics::Model& model, int step,
                                     const DynamicsStepOptions& options, const DfgKeys& keys) {
  std::vector<int> joints;
  DynamicsStepFactor::rows_for(model, options, &joints);
  detail::DfgLayout l;
  for (int j : joints) {
    const JointScalar s = keys.torque_scalar(j, step, model.nq());
    if (std::find(l.keys.begin(), l.keys.end(), s.key) == l.keys.end()) {
      l.keys.push_back(s.key);
      l.dims.push_back(s.dim);
    }
  }
  return l;
}

}  // namespace

DfgConstraintFactor::DfgConstraintFactor(graph::FactorPtr equation, double scale)
    : ConstrainedFactor(equation ? equation->keys() : std::vector<graph::Key>{},
                        equation ? equation->dims() : std::vector<int>{},
                        equality_rows(equation, scale)),
      equation_(std::move(equation)) {}

void DfgConstraintFactor::compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
                                  const graph::Jacobians* J) const {
  equation_->evaluate(x, z, J);
}

std::string DfgConstraintFactor::name() const { return "DfgConstraint<" + equation_->name() + ">"; }

DfgTorqueRowsFactor::DfgTorqueRowsFactor(const dynamics::Model& model, int step,
                                         const DynamicsStepOptions& options, const DfgKeys& keys)
    : ConstrainedFactor(torque_rows_layout(model, step, options, keys).keys,
                        torque_rows_layout(model, step, options, keys).dims,
                        torque_rows_checked(model, options)) {
  std::vector<int> joints;
  DynamicsStepFactor::rows_for(model, options, &joints);
  for (int j : joints) {
    const JointScalar s = keys.torque_scalar(j, step, model.nq());
    slot_of_row_.push_back(static_cast<int>(
        std::find(this->keys().begin(), this->keys().end(), s.key) - this->keys().begin()));
    comp_of_row_.push_back(s.component);
  }
}

void DfgTorqueRowsFactor::compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
                                  const graph::Jacobians* J) const {
  for (size_t r = 0; r < slot_of_row_.size(); ++r) {
    const int row = static_cast<int>(r);
    z[row] = x[slot_of_row_[r]][comp_of_row_[r]];
    if (J != nullptr) J->block(slot_of_row_[r])(row, comp_of_row_[r]) = 1.0;
  }
}

DfgConstraintStep add_dfg_constraints(graph::FactorGraph& graph, graph::Values& values,
                                      const dynamics::Model& model, dynamics::Data& data, int step,
                                      const DynamicsStepOptions& torque_rows,
                                      const DfgOptions& options) {
  const DfgKeys& k = options.keys;
  // Copies: inserting the new variables may move the storage the views point into.
  const Eigen::VectorXd q = values.at(k.q_key(step)), qd = values.at(k.qd_key(step)),
                        qdd = values.at(k.qdd_key(step));
  set_dfg_values(values, model, data, step, q, qd, qdd, options);
  const StepFactors f = make_step_factors(model, step, options, nullptr, nullptr);
  DfgConstraintStep out;
  out.step = step;
  auto add = [&](std::shared_ptr<ConstrainedFactor> c) {
    out.indices.push_back(graph.add(c));
    out.factors.push_back(std::move(c));
  };
  for (const auto* kind : {&f.twist, &f.accel, &f.wrench, &f.torque}) {
    for (const graph::FactorPtr& e : *kind) {
      add(std::make_shared<DfgConstraintFactor>(e, options.constraint_scale));
    }
  }
  if (!DynamicsStepFactor::rows_for(model, torque_rows).empty()) {
    add(std::make_shared<DfgTorqueRowsFactor>(model, step, torque_rows, k));
  }
  return out;
}

std::vector<DfgConstraintStep> use_dfg_dynamics(PlanningGraph& pg, const Problem& problem,
                                                const GraphOptions& graph_options,
                                                const DfgOptions& options) {
  if (!problem.model) throw std::invalid_argument("use_dfg_dynamics: problem has no model");
  std::vector<int> steps;
  std::vector<FactorEntry> kept;
  for (FactorEntry& e : pg.entries) {
    if (e.key.role != FactorRole::kDynamics) {
      kept.push_back(std::move(e));
      continue;
    }
    steps.push_back(e.key.step);
    if (!e.anchor) pg.graph.remove(e.slot);
  }
  pg.entries = std::move(kept);
  // The rows build_graph gives the condensed factor.
  DynamicsStepOptions rows;
  rows.limit_epsilon = problem.objectives.limit_epsilon;
  rows.min_torque = problem.objectives.min_torque;
  rows.torque_scale = graph_options.torque_scale;
  if (!pg.dynamics_workspace) {
    pg.dynamics_workspace = std::make_shared<DynamicsWorkspace>(problem.model);
  }
  std::vector<DfgConstraintStep> out;
  graph::FactorGraph scratch;  // add_dfg_constraints' indices are not needed here
  for (int k : steps) {
    out.push_back(add_dfg_constraints(scratch, pg.values, *problem.model, pg.dynamics_workspace->local(),
                                      k, rows, options));
    DfgConstraintStep& step = out.back();
    step.indices.clear();
    for (size_t i = 0; i < step.factors.size(); ++i) {
      pg.add(make_entry(step.factors[i], {FactorRole::kDynamics, k, static_cast<int>(i)}));
      step.indices.push_back(pg.entries.back().slot);
    }
  }
  return out;
}

Plan plan_from_values(const Problem& problem, const graph::Values& values, const DfgKeys& keys) {
  Plan plan =
      plan_from_trajectory(problem, read_trajectory(values, problem.steps, problem.model->nq()));
  read_dfg_torques(plan, values, *problem.model, keys);
  return plan;
}

void read_dfg_torques(Plan& plan, const graph::Values& values, const dynamics::Model& model,
                      const DfgKeys& keys) {
  for (int k = 0; k < plan.tau.rows(); ++k) {
    if (values.contains(keys.torque_key(0, k))) {
      plan.tau.row(k) = dfg_torques(values, model, k, keys).transpose();
    }
  }
}

Eigen::VectorXd dfg_torques(const graph::Values& values, const dynamics::Model& model, int step,
                            const DfgKeys& keys) {
  const int n = model.nq();
  if (keys.torque_vector) return values.at(keys.torque_key(0, step));
  Eigen::VectorXd tau(n);
  for (int i = 0; i < n; ++i) tau[i] = values.at(keys.torque_key(i, step))[0];
  return tau;
}

std::string DfgTorqueRowsFactor::describe_row(int row, double z, const RowContext& c) const {
  // The condensed factor's rows: its constraint rows come first and do not depend on the
  // margins or the soft weight.
  std::vector<int> joints;
  DynamicsStepFactor::rows_for(c.model, DynamicsStepOptions{}, &joints);
  if (row >= static_cast<int>(joints.size())) return "";
  const RowSpec& spec = rows()[static_cast<size_t>(row)];
  return torque_text(c.model, joints[static_cast<size_t>(row)], spec.kind == RowKind::kEquality,
                     z, spec.lower, spec.upper, c.violation, c.t);
}

}  // namespace kinograph::planning

#include "kinograph/planning/factors/dynamics_factors.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/planning/factors/trajectory_factors.h"
#include "kinograph/planning/user_terms.h"

namespace kinograph::planning {

std::vector<RowSpec> DynamicsStepFactor::rows_for(const dynamics::Model& model,
                                                  const DynamicsStepOptions& options,
                                                  std::vector<int>* joint_of_row) {
  std::vector<RowSpec> rows;
  std::vector<int> joints;
  rows.reserve(2 * model.nq());
  joints.reserve(2 * model.nq());
  for (int j = 0; j < model.nq(); ++j) {
    const dynamics::Body& b = model.bodies[j];
    RowSpec r;
    r.scale = options.torque_scale;
    if (!b.actuated) {
      r.kind = RowKind::kEquality;
      r.lower = 0;
    } else if (std::isfinite(b.limits.effort)) {
      r.kind = RowKind::kBounds;
      const double e = std::max(0.0, b.limits.effort - options.limit_epsilon);
      r.lower = -e;
      r.upper = e;
    } else {
      continue;
    }
    rows.push_back(r);
    joints.push_back(j);
  }
  if (options.min_torque > 0) {
    for (int j = 0; j < model.nq(); ++j) {
      RowSpec r;
      r.kind = RowKind::kSoft;
      r.weight = std::sqrt(2 * options.min_torque);
      rows.push_back(r);
      joints.push_back(j);
    }
  }
  if (joint_of_row != nullptr) *joint_of_row = std::move(joints);
  return rows;
}

DynamicsStepFactor::DynamicsStepFactor(int k, std::shared_ptr<const dynamics::Model> model,
                                       std::shared_ptr<DynamicsWorkspace> workspace,
                                       const DynamicsStepOptions& options)
    : ConstrainedFactor({q_key(k), v_key(k), a_key(k)}, {model->nq(), model->nq(), model->nq()},
                        rows_for(*model, options)),
      model_(std::move(model)),
      data_(std::move(workspace)) {
  rows_for(*model_, options, &joint_of_row_);
  bounds_only_ = std::all_of(rows().begin(), rows().end(),
                             [](const RowSpec& r) { return r.kind == RowKind::kBounds; });
  cache_evaluations();
}

void DynamicsStepFactor::compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
                                 const graph::Jacobians* J) const {
  dynamics::Data& d = data_->local();
  // Torque bounds alone, every hinge off: no Jacobian row is needed, and τ alone costs about a
  // third of τ with its derivatives.
  bool derivatives = J != nullptr;
  if (!derivatives || bounds_only_) {
    dynamics::rnea(*model_, d, x[0], x[1], x[2]);
    bool needed = false;
    for (size_t i = 0; derivatives && !needed && i < joint_of_row_.size(); ++i) {
      needed = jacobian_row_needed(static_cast<int>(i), d.tau[joint_of_row_[i]]);
    }
    derivatives = needed;
  }
  if (derivatives) dynamics::rnea_derivatives(*model_, d, x[0], x[1], x[2]);
  for (size_t i = 0; i < joint_of_row_.size(); ++i) {
    const int j = joint_of_row_[i];
    z[static_cast<int>(i)] = d.tau[j];
    if (derivatives) {
      const int r = static_cast<int>(i);
      J->block(0).row(r) = d.dtau_dq.row(j);
      J->block(1).row(r) = d.dtau_dqd.row(j);
      J->block(2).row(r) = d.M.row(j);
    }
  }
}

std::string DynamicsStepFactor::describe_row(int row, double z, const RowContext& c) const {
  const RowSpec& spec = rows()[static_cast<size_t>(row)];
  return torque_text(c.model, joint_of_row_[static_cast<size_t>(row)],
                     spec.kind == RowKind::kEquality, z, spec.lower, spec.upper, c.violation, c.t);
}

}  // namespace kinograph::planning

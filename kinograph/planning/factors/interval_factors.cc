#include "kinograph/planning/factors/interval_factors.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "kinograph/planning/factors/trajectory_factors.h"
#include "kinograph/planning/user_terms.h"

namespace kinograph::planning {
namespace {

std::vector<RowSpec> row_specs(const dynamics::Model& model, double dt,
                               const IntervalDynamicsOptions& o) {
  using Kind = IntervalDynamicsFactor::Row::Kind;
  const std::vector<IntervalDynamicsFactor::Row> layout = IntervalDynamicsFactor::layout(model, o);
  std::vector<RowSpec> rows;
  rows.reserve(layout.size());
  for (const IntervalDynamicsFactor::Row& r : layout) {
    const dynamics::JointLimits& l = model.bodies[r.joint].limits;
    const double e = o.limit_epsilon;
    RowSpec spec;
    switch (r.kind) {
      case Kind::kDefectQ: spec.scale = o.defect_scale * dt * dt; break;
      case Kind::kDefectQd: spec.scale = o.defect_scale * dt; break;
      case Kind::kTau: {
        const double m = std::max(0.0, l.effort - e);
        spec = {RowKind::kBounds, -m, m, o.torque_scale};
        break;
      }
      case Kind::kQ: spec = {RowKind::kBounds, l.lower + e, l.upper - e, o.limit_scale}; break;
      case Kind::kQd:
        spec = {RowKind::kBounds, -l.velocity + e, l.velocity - e, o.limit_scale};
        break;
    }
    rows.push_back(spec);
  }
  if (rows.empty()) throw std::invalid_argument("IntervalDynamicsFactor would have no rows");
  return rows;
}

}  // namespace

std::vector<IntervalDynamicsFactor::Row> IntervalDynamicsFactor::layout(
    const dynamics::Model& model, const IntervalDynamicsOptions& o) {
  std::vector<Row> rows;
  rows.reserve(2 * model.nq() + 3 * model.nq() * std::max(0, o.checks));
  for (int j = 0; j < model.nq(); ++j) {
    if (!model.bodies[j].actuated) rows.push_back({Row::Kind::kDefectQ, j, -1});
  }
  for (int j = 0; j < model.nq(); ++j) {
    if (!model.bodies[j].actuated) rows.push_back({Row::Kind::kDefectQd, j, -1});
  }
  const bool effort = (o.limit_rows & kEffortLimitRows) != 0;
  const bool motion = (o.limit_rows & kMotionLimitRows) != 0;
  for (int i = 0; i < o.checks; ++i) {
    for (int j = 0; j < model.nq(); ++j) {
      const dynamics::Body& b = model.bodies[j];
      if (effort && b.actuated && std::isfinite(b.limits.effort)) {
        rows.push_back({Row::Kind::kTau, j, i});
      }
      if (!motion) continue;
      if (std::isfinite(b.limits.lower) || std::isfinite(b.limits.upper))
        rows.push_back({Row::Kind::kQ, j, i});
      if (std::isfinite(b.limits.velocity)) rows.push_back({Row::Kind::kQd, j, i});
    }
  }
  return rows;
}

IntervalDynamicsFactor::IntervalDynamicsFactor(int k, double dt,
                                               std::shared_ptr<const dynamics::Model> model,
                                               const IntervalDynamicsOptions& options,
                                               std::shared_ptr<IntervalWorkspace> workspace)
    : ConstrainedFactor({q_key(k), v_key(k), a_key(k), q_key(k + 1), v_key(k + 1), a_key(k + 1)},
                        std::vector<int>(6, model->nq()),
                        (dt > 0 ? row_specs(*model, dt, options)
                                : throw std::invalid_argument("IntervalDynamicsFactor: dt <= 0"))),
      model_(std::move(model)),
      dt_(dt),
      layout_(layout(*model_, options)),
      workspace_(workspace ? std::move(workspace)
                           : std::make_shared<IntervalWorkspace>(model_, options.integration_step)) {
  if (workspace_->model() != model_ || workspace_->integration_step() != options.integration_step) {
    throw std::invalid_argument("IntervalDynamicsFactor: the workspace is for another model or "
                                "RK4 step");
  }
  while (defect_rows_ < static_cast<int>(layout_.size()) && layout_[defect_rows_].point < 0) {
    ++defect_rows_;
  }
  // Check points only where they have rows (limit_rows may leave a robot's points none).
  const int checks = defect_rows_ < static_cast<int>(layout_.size()) ? options.checks : 0;
  times_.reserve(checks + 1);
  point_begin_.reserve(checks + 1);
  for (int i = 1; i <= checks; ++i) times_.push_back(dt * i / (checks + 1));
  times_.push_back(dt);
  int row = defect_rows_;
  for (int i = 0; i < checks; ++i) {
    point_begin_.push_back(row);
    while (row < static_cast<int>(layout_.size()) && layout_[row].point == i) ++row;
  }
  point_begin_.push_back(row);
  for (const Row& r : layout_) effort_rows_ = effort_rows_ || r.kind == Row::Kind::kTau;
  // Rows on the interpolant alone cost little to recompute, and few of them are ever near a
  // limit: such a factor lists the rows it writes instead of keeping a copy of its Jacobian.
  if (defect_rows_ == 0 && !effort_rows_) {
    list_written_rows();
  } else {
    cache_evaluations();
  }
}

void IntervalDynamicsFactor::jacobian_row(int row, const Eigen::MatrixXd& d, double sign,
                                          const graph::Jacobians& J, bool whole) const {
  const int n = model_->nq(), j = layout_[static_cast<size_t>(row)].joint;
  // d's blocks 0, 1, 2 are q_k, q̇_k, q̈_k; its fourth, q̈_{k+1}, is key 5.
  const int key_of[4] = {0, 1, 2, 5};
  if (whole) {  // J arrived unzeroed: the row is written in full, q_{k+1} and q̇_{k+1} as zeros
    J.block(3).row(row).setZero();
    J.block(4).row(row).setZero();
    for (int b = 0; b < 4; ++b) J.block(key_of[b]).row(row) = sign * d.block(j, b * n, 1, n);
    return;
  }
  for (int b = 0; b < 4; ++b) J.block(key_of[b]).row(row) += sign * d.block(j, b * n, 1, n);
}

void IntervalDynamicsFactor::compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
                                     const graph::Jacobians* J) const {
  using Kind = Row::Kind;
  const int checks = static_cast<int>(times_.size()) - 1;
  // The defect needs the sensitivities to the end; check points only if a row of theirs is on.
  const bool derivatives = J != nullptr;
  IntervalScratch& w = workspace_->local();
  IntervalInterpolant& interpolant = w.interpolant;
  std::vector<InterpolantPoint>& points = w.points;
  if (points.size() < times_.size()) points.resize(times_.size());  // grow only: keeps storage
  interpolant.start(x[0], x[1], x[2], x[5], dt_, derivatives);
  for (int i = 0; i < checks; ++i) interpolant.at(times_[i], false, points[i], effort_rows_);
  // The value of a row at a point.
  const auto value = [&](const Row& r, const InterpolantPoint& p) {
    switch (r.kind) {
      case Kind::kTau: return p.tau[r.joint];
      case Kind::kQ: return p.q[r.joint];
      default: return p.qd[r.joint];
    }
  };
  // Defect rows come in unactuated() order, positions first: row i reads y[i] and S.row(i).
  const Eigen::VectorXd& y = interpolant.end_state();
  for (int row = 0; row < defect_rows_; ++row) {
    const Row& r = layout_[row];
    const int block = r.kind == Kind::kDefectQ ? 3 : 4;
    z[row] = x[block][r.joint] - y[row];
    if (!derivatives) continue;
    J->block(block)(row, r.joint) = 1;
    const Eigen::MatrixXd& S = interpolant.end_sensitivity();
    const int n = model_->nq(), key_of[4] = {0, 1, 2, 5};
    for (int b = 0; b < 4; ++b) J->block(key_of[b]).row(row) -= S.block(row, b * n, 1, n);
  }
  // With list_written_rows() and a row list, J arrives unzeroed and the rows written are listed.
  graph::RowSupport* listed =
      derivatives && writes_listed_rows_only() ? J->row_support() : nullptr;
  bool within = defect_rows_ == 0;  // every row so far strictly inside its bounds
  for (int i = 0; i < checks; ++i) {
    bool needed = false, tau_needed = false;  // a row of the point needs its Jacobian row
    for (int row = point_begin_[i]; row < point_begin_[i + 1]; ++row) {
      z[row] = value(layout_[row], points[i]);
      const RowSpec& spec = rows()[static_cast<size_t>(row)];
      within = within && z[row] > spec.lower && z[row] < spec.upper;
      if (derivatives && jacobian_row_needed(row, z[row])) {
        needed = true;
        tau_needed = tau_needed || layout_[row].kind == Kind::kTau;
      }
    }
    if (!needed) continue;
    // Position and velocity rows alone need no dynamics' derivatives.
    interpolant.at(times_[i], true, w.with_derivatives, tau_needed);
    for (int row = point_begin_[i]; row < point_begin_[i + 1]; ++row) {
      if (!jacobian_row_needed(row, z[row])) continue;
      const Kind kind = layout_[row].kind;
      if (listed != nullptr) listed->rows.push_back(row);
      jacobian_row(row,
                   kind == Kind::kTau  ? w.with_derivatives.dtau
                   : kind == Kind::kQ ? w.with_derivatives.dq
                                      : w.with_derivatives.dqd,
                   1, *J, listed != nullptr);
    }
  }
  // Limit rows only, all inside their bounds with no multiplier pressing: every hinge is off.
  if (within && bound_multipliers_zero()) rows_proven_clear();
}

std::string IntervalDynamicsFactor::describe_row(int row, double z, const RowContext& c) const {
  const Row& r = layout_[static_cast<size_t>(row)];
  const RowSpec& spec = rows()[static_cast<size_t>(row)];
  if (r.kind == Row::Kind::kDefectQ || r.kind == Row::Kind::kDefectQd) {
    const int derivative = r.kind == Row::Kind::kDefectQ ? 0 : 1;
    return joint_label(c.model, r.joint) + ", unactuated, follows its dynamics from " +
           at_time(c.t) + " and arrives at " + at_time(c.t + dt_) + " " + number(c.violation) +
           " " + joint_unit(c.model, r.joint, derivative) + " off the next knot's " +
           (derivative == 0 ? "position" : "velocity");
  }
  const double t = c.t + times_[static_cast<size_t>(r.point)];
  const int derivative = r.kind == Row::Kind::kQ ? 0 : r.kind == Row::Kind::kQd ? 1 : 3;
  return limit_text(c.model, derivative, r.joint, z, spec.lower, spec.upper, c.violation, t) +
         " (between the knots)";
}

}  // namespace kinograph::planning

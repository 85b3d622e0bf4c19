#include "kinograph/planning/factors/interval_factors.h"

#include <cmath>
#include <stdexcept>

#include "kinograph/planning/factors/trajectory_factors.h"

namespace kinograph::planning {
namespace {

std::vector<RowSpec> row_specs(const dynamics::Model& model, double dt,
                               const IntervalDynamicsOptions& o) {
  using Kind = IntervalDynamicsFactor::Row::Kind;
  std::vector<RowSpec> rows;
  for (const IntervalDynamicsFactor::Row& r : IntervalDynamicsFactor::layout(model, o)) {
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
  for (int j = 0; j < model.nq(); ++j) {
    if (!model.bodies[j].actuated) rows.push_back({Row::Kind::kDefectQ, j, -1});
  }
  for (int j = 0; j < model.nq(); ++j) {
    if (!model.bodies[j].actuated) rows.push_back({Row::Kind::kDefectQd, j, -1});
  }
  for (int i = 0; i < o.checks; ++i) {
    for (int j = 0; j < model.nq(); ++j) {
      const dynamics::Body& b = model.bodies[j];
      if (b.actuated && std::isfinite(b.limits.effort)) rows.push_back({Row::Kind::kTau, j, i});
      if (std::isfinite(b.limits.lower) || std::isfinite(b.limits.upper))
        rows.push_back({Row::Kind::kQ, j, i});
      if (std::isfinite(b.limits.velocity)) rows.push_back({Row::Kind::kQd, j, i});
    }
  }
  return rows;
}

IntervalDynamicsFactor::IntervalDynamicsFactor(int k, double dt,
                                               std::shared_ptr<const dynamics::Model> model,
                                               const IntervalDynamicsOptions& options)
    : ConstrainedFactor({q_key(k), v_key(k), a_key(k), q_key(k + 1), v_key(k + 1), a_key(k + 1)},
                        std::vector<int>(6, model->nq()),
                        (dt > 0 ? row_specs(*model, dt, options)
                                : throw std::invalid_argument("IntervalDynamicsFactor: dt <= 0"))),
      model_(std::move(model)),
      dt_(dt),
      layout_(layout(*model_, options)),
      interpolant_(*model_) {
  for (int i = 1; i <= options.checks; ++i) times_.push_back(dt * i / (options.checks + 1));
  times_.push_back(dt);
}

void IntervalDynamicsFactor::compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
                                     const graph::Jacobians* J) const {
  using Kind = Row::Kind;
  const int n = model_->nq();
  interpolant_.evaluate(x[0], x[1], x[2], x[5], dt_, times_, J != nullptr, points_);
  const InterpolantPoint& end = points_.back();
  for (size_t i = 0; i < layout_.size(); ++i) {
    const Row& r = layout_[i];
    const int row = static_cast<int>(i), j = r.joint;
    // The value's derivative row with respect to z = [q_k; q̇_k; q̈_k; q̈_{k+1}], and its sign.
    const Eigen::MatrixXd* d = nullptr;
    double sign = 1;
    switch (r.kind) {
      case Kind::kDefectQ:
        z[row] = x[3][j] - end.q[j];
        d = &end.dq;
        sign = -1;
        break;
      case Kind::kDefectQd:
        z[row] = x[4][j] - end.qd[j];
        d = &end.dqd;
        sign = -1;
        break;
      case Kind::kTau:
        z[row] = points_[r.point].tau[j];
        d = &points_[r.point].dtau;
        break;
      case Kind::kQ:
        z[row] = points_[r.point].q[j];
        d = &points_[r.point].dq;
        break;
      case Kind::kQd:
        z[row] = points_[r.point].qd[j];
        d = &points_[r.point].dqd;
        break;
    }
    if (J == nullptr) continue;
    if (r.kind == Kind::kDefectQ) J->block(3)(row, j) = 1;
    if (r.kind == Kind::kDefectQd) J->block(4)(row, j) = 1;
    // z's blocks 0, 1, 2 are q_k, q̇_k, q̈_k; its fourth, q̈_{k+1}, is key 5.
    const int key_of[4] = {0, 1, 2, 5};
    for (int b = 0; b < 4; ++b) J->block(key_of[b]).row(row) += sign * d->block(j, b * n, 1, n);
  }
}

}  // namespace kinograph::planning

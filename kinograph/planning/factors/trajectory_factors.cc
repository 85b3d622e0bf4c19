#include "kinograph/planning/factors/trajectory_factors.h"
#include "kinograph/planning/user_terms.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <stdexcept>
#include <string>

namespace kinograph::planning {

graph::Key q_key(int k) { return graph::Key('q', 0, static_cast<uint32_t>(k)); }
graph::Key v_key(int k) { return graph::Key('v', 0, static_cast<uint32_t>(k)); }
graph::Key a_key(int k) { return graph::Key('a', 0, static_cast<uint32_t>(k)); }

Eigen::Matrix3d gp_transition(double dt) {
  Eigen::Matrix3d phi;
  phi << 1, dt, 0.5 * dt * dt, 0, 1, dt, 0, 0, 1;
  return phi;
}

Eigen::Matrix3d gp_covariance(double dt, double qc) {
  const double d2 = dt * dt, d3 = d2 * dt, d4 = d3 * dt, d5 = d4 * dt;
  Eigen::Matrix3d Q;
  Q << d5 / 20, d4 / 8, d3 / 6, d4 / 8, d3 / 3, d2 / 2, d3 / 6, d2 / 2, dt;
  return qc * Q;
}

namespace {
std::vector<graph::Key> two_state_keys(int k) {
  return {q_key(k), v_key(k), a_key(k), q_key(k + 1), v_key(k + 1), a_key(k + 1)};
}
}  // namespace

GpPriorFactor::GpPriorFactor(int k, int n, double dt, double qc)
    : graph::Factor(two_state_keys(k), std::vector<int>(6, n), 3 * n),
      n_(n),
      phi_(gp_transition(dt)) {
  if (!(dt > 0) || !(qc > 0)) throw std::invalid_argument("GP prior needs dt > 0 and Qc > 0");
  const Eigen::Matrix3d info = gp_covariance(dt, qc).inverse();
  // R upper triangular with RᵀR = Q⁻¹: the transposed lower Cholesky factor.
  R_ = info.llt().matrixU();
  set_linear();
}

void GpPriorFactor::evaluate(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                             const graph::Jacobians* J) const {
  // Rows are grouped per joint: (q, q̇, q̈) of joint j at rows 3j..3j+2.
  for (int j = 0; j < n_; ++j) {
    const Eigen::Vector3d x0(x[0][j], x[1][j], x[2][j]);
    const Eigen::Vector3d x1(x[3][j], x[4][j], x[5][j]);
    e.segment<3>(3 * j) = R_ * (x1 - phi_ * x0);
  }
  if (J == nullptr) return;
  const Eigen::Matrix3d A = -R_ * phi_;  // d/dx_k; d/dx_{k+1} is R
  for (int c = 0; c < 3; ++c) {
    auto B0 = J->block(c);
    auto B1 = J->block(3 + c);
    for (int j = 0; j < n_; ++j) {
      B0.block<3, 1>(3 * j, j) = A.col(c);
      B1.block<3, 1>(3 * j, j) = R_.col(c);
    }
  }
}

namespace {
std::vector<int> all_or(std::vector<int> joints, int n) {
  if (joints.empty()) {
    for (int j = 0; j < n; ++j) joints.push_back(j);
  }
  for (int j : joints) {
    if (j < 0 || j >= n) throw std::invalid_argument("CollocationFactor: no joint " + std::to_string(j));
  }
  return joints;
}

std::vector<RowSpec> collocation_rows(int m, double dt, double scale) {
  std::vector<RowSpec> rows(2 * m);
  for (int i = 0; i < m; ++i) {
    rows[i].scale = scale * dt * dt;
    rows[m + i].scale = scale * dt;
  }
  return rows;
}
}  // namespace

CollocationFactor::CollocationFactor(int k, int n, double dt, double scale,
                                     std::vector<int> joints)
    : ConstrainedFactor(two_state_keys(k), std::vector<int>(6, n),
                        collocation_rows(static_cast<int>(all_or(joints, n).size()), dt, scale)),
      n_(n),
      dt_(dt),
      joints_(all_or(std::move(joints), n)) {
  declare_linear();
}

void CollocationFactor::compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
                                const graph::Jacobians* J) const {
  const double h = dt_, h2 = dt_ * dt_;
  const int m = static_cast<int>(joints_.size());
  for (int i = 0; i < m; ++i) {
    const int j = joints_[i];
    z[i] = x[3][j] - x[0][j] - h * x[1][j] - h2 / 6 * (2 * x[2][j] + x[5][j]);
    z[m + i] = x[4][j] - x[1][j] - 0.5 * h * (x[2][j] + x[5][j]);
    if (J == nullptr) continue;
    J->block(0)(i, j) = -1;
    J->block(1)(i, j) = -h;
    J->block(2)(i, j) = -h2 / 3;
    J->block(3)(i, j) = 1;
    J->block(5)(i, j) = -h2 / 6;
    J->block(1)(m + i, j) = -1;
    J->block(2)(m + i, j) = -0.5 * h;
    J->block(4)(m + i, j) = 1;
    J->block(5)(m + i, j) = -0.5 * h;
  }
}

namespace {
std::vector<RowSpec> limit_rows(const std::vector<StateLimitFactor::Limit>& limits, double scale) {
  if (limits.empty()) throw std::invalid_argument("StateLimitFactor needs at least one limit");
  std::vector<RowSpec> rows(limits.size());
  for (size_t i = 0; i < limits.size(); ++i) {
    rows[i].kind = RowKind::kBounds;
    rows[i].lower = limits[i].lower;
    rows[i].upper = limits[i].upper;
    rows[i].scale = scale;
  }
  return rows;
}
}  // namespace

StateLimitFactor::StateLimitFactor(int k, int n, std::vector<Limit> limits, double scale)
    : ConstrainedFactor({q_key(k), v_key(k), a_key(k)}, {n, n, n}, limit_rows(limits, scale)),
      limits_(std::move(limits)) {}

void StateLimitFactor::compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
                               const graph::Jacobians* J) const {
  for (size_t i = 0; i < limits_.size(); ++i) {
    const Limit& l = limits_[i];
    z[i] = x[l.variable][l.joint];
    if (J != nullptr) J->block(l.variable)(static_cast<int>(i), l.joint) = 1;
  }
}

std::string CollocationFactor::describe_row(int row, double, const RowContext& c) const {
  const int m = static_cast<int>(joints_.size());
  const int j = joints_[static_cast<size_t>(row % m)], derivative = row < m ? 0 : 1;
  return joint_label(c.model, j) + (derivative == 0 ? " position" : " velocity") + " between " +
         at_time(c.t) + " and " + number(c.t + c.dt) + " s disagrees with its " +
         (derivative == 0 ? "velocity and acceleration" : "acceleration") + " by " +
         number(c.violation) + " " + joint_unit(c.model, j, derivative);
}

std::string StateLimitFactor::describe_row(int row, double z, const RowContext& c) const {
  const Limit& l = limits_[static_cast<size_t>(row)];
  return limit_text(c.model, l.variable, l.joint, z, l.lower, l.upper, c.violation, c.t);
}

}  // namespace kinograph::planning

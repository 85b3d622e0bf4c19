#include "kinograph/planning/interpolant.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "kinograph/dynamics/inverse_dynamics.h"

namespace kinograph::planning {

int integration_steps(double dt, double max_step) {
  // The small allowance keeps Δt = 0.1 s at 10 steps despite rounding in Δt = horizon/steps.
  return std::max(1, static_cast<int>(std::ceil(dt / max_step - 1e-9)));
}

int limit_points(int requested, double dt) {
  if (requested <= 0) return 0;
  return std::max(requested, integration_steps(dt) - 1);
}

void actuated_turning_times(double qd0, double qdd0, double qdd1, double dt,
                            std::vector<double>& out) {
  const auto keep = [&](double s) {
    if (s > 0 && s < dt) out.push_back(s);
  };
  // q̈(s) = q̈0 + (q̈1 − q̈0) s / Δt and q̇(s) = q̇0 + q̈0 s + (q̈1 − q̈0) s² / (2Δt).
  const double jerk = (qdd1 - qdd0) / dt;
  if (jerk != 0) keep(-qdd0 / jerk);
  const double a = jerk / 2, b = qdd0, c = qd0;
  if (a == 0) {
    if (b != 0) keep(-c / b);
    return;
  }
  const double disc = b * b - 4 * a * c;
  if (!(disc >= 0)) return;
  // The root of larger magnitude first, the other from their product: no cancellation. (q = 0
  // only for the double root s = 0.)
  const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
  if (q == 0) return;
  keep(q / a);
  keep(c / q);
}

IntervalInterpolant::IntervalInterpolant(const dynamics::Model& model, double max_step)
    : model_(model), max_step_(max_step), coarse_(max_step > kMaxIntegrationStep), data_(model) {
  if (!(max_step > 0)) throw std::invalid_argument("interpolant: the RK4 step must be > 0");
  for (int j = 0; j < model.nq(); ++j) {
    (model.bodies[j].actuated ? actuated_ : unactuated_).push_back(j);
  }
  const int n = model.nq(), m = static_cast<int>(unactuated_.size());
  q0_.setZero(n);
  qd0_.setZero(n);
  qdd0_.setZero(n);
  qdd1_.setZero(n);
  rhs_.resize(m, 4 * n);
  for (int i = 0; i < 4; ++i) {
    k_[i].resize(2 * m);
    dk_[i].resize(2 * m, 4 * n);
  }
  ys_.resize(2 * m);
  y_part_.resize(2 * m);
  Ss_.resize(2 * m, 4 * n);
  S_part_.resize(2 * m, 4 * n);
}

void IntervalInterpolant::point(double s, const Eigen::VectorXd& y, const Eigen::MatrixXd& S,
                                bool derivatives, bool with_tau, InterpolantPoint& p) {
  const int n = model_.nq(), m = static_cast<int>(unactuated_.size());
  const double h = dt_;
  // Cubic with linear q̈: coefficients of (q_k, q̇_k, q̈_k, q̈_{k+1}) in q, q̇ and q̈ at s.
  const double s2 = s * s, s3 = s2 * s;
  const double cq[4] = {1, s, s2 / 2 - s3 / (6 * h), s3 / (6 * h)};
  const double cv[4] = {0, 1, s - s2 / (2 * h), s2 / (2 * h)};
  const double ca[4] = {0, 0, 1 - s / h, s / h};
  p.s = s;
  p.q = cq[0] * q0_ + cq[1] * qd0_ + cq[2] * qdd0_ + cq[3] * qdd1_;
  p.qd = cv[1] * qd0_ + cv[2] * qdd0_ + cv[3] * qdd1_;
  p.qdd = ca[2] * qdd0_ + ca[3] * qdd1_;
  if (derivatives) {
    p.dq.setZero(n, 4 * n);
    p.dqd.setZero(n, 4 * n);
    p.dqdd.setZero(n, 4 * n);
    for (int j : actuated_) {
      for (int b = 0; b < 4; ++b) {
        p.dq(j, b * n + j) = cq[b];
        p.dqd(j, b * n + j) = cv[b];
        p.dqdd(j, b * n + j) = ca[b];
      }
    }
  }
  for (int i = 0; i < m; ++i) {
    const int j = unactuated_[i];
    p.q[j] = y[i];
    p.qd[j] = y[m + i];
    p.qdd[j] = 0;
    if (derivatives) {
      p.dq.row(j) = S.row(i);
      p.dqd.row(j) = S.row(m + i);
    }
  }
  if (m == 0) {
    if (!with_tau) return;  // the cubic needs no dynamics
    if (derivatives) {
      dynamics::rnea_derivatives(model_, data_, p.q, p.qd, p.qdd);
      // Each input block b moves every joint by the same coefficient: dτ_b = Σ c_b ∂τ/∂x.
      p.dtau.resize(n, 4 * n);
      for (int b = 0; b < 4; ++b) {
        p.dtau.middleCols(b * n, n) = cq[b] * data_.dtau_dq + cv[b] * data_.dtau_dqd;
        p.dtau.middleCols(b * n, n) += ca[b] * data_.M;
      }
    } else {
      dynamics::rnea(model_, data_, p.q, p.qd, p.qdd);
    }
    p.tau = data_.tau;
    return;
  }
  // q̈_u makes τ_u zero, with the torques, M and (derivatives) ∂τ at that q̈ in one pass.
  dynamics::passive_dynamics(model_, data_, p.q, p.qd, p.qdd, unactuated_, derivatives);
  p.tau = data_.tau;
  for (int i = 0; i < m; ++i) p.qdd[unactuated_[i]] = data_.qdd[unactuated_[i]];
  if (!derivatives) return;
  // Implicit function τ_u(q, q̇, q̈_a, q̈_u) = 0: dq̈_u = −M_uu⁻¹(∂τ_u/∂q dq + ∂τ_u/∂q̇ dq̇ +
  // M_ua dq̈_a), where dq̈ holds only the actuated rows so far.
  for (int i = 0; i < m; ++i) {
    const int u = unactuated_[i];
    rhs_.row(i).noalias() = data_.dtau_dq.row(u) * p.dq;
    rhs_.row(i).noalias() += data_.dtau_dqd.row(u) * p.dqd;
    rhs_.row(i).noalias() += data_.M.row(u) * p.dqdd;
  }
  // passive_dynamics left M_uu's Cholesky factor in its scratch; one joint divides instead.
  if (m == 1) {
    rhs_ /= data_.M(unactuated_[0], unactuated_[0]);
  } else {
    data_.scratch.llt_p.solveInPlace(rhs_);
  }
  for (int i = 0; i < m; ++i) p.dqdd.row(unactuated_[i]) = -rhs_.row(i);
  if (with_tau) {
    p.dtau.noalias() = data_.dtau_dq * p.dq;
    p.dtau.noalias() += data_.dtau_dqd * p.dqd;
    p.dtau.noalias() += data_.M * p.dqdd;
  }
}

void IntervalInterpolant::slope(double s, const Eigen::VectorXd& y, const Eigen::MatrixXd& S,
                                bool derivatives, Eigen::VectorXd& k, Eigen::MatrixXd& dk) {
  const int m = static_cast<int>(unactuated_.size());
  point(s, y, S, derivatives, false, stage_);
  for (int a = 0; a < m; ++a) {
    const int u = unactuated_[a];
    k[a] = stage_.qd[u];
    k[m + a] = stage_.qdd[u];
    if (derivatives) {
      dk.row(a) = stage_.dqd.row(u);
      dk.row(m + a) = stage_.dqdd.row(u);
    }
  }
}

void IntervalInterpolant::hermite(int node, double rest, bool derivatives) {
  const int want = derivatives ? 2 : 1;
  if (node + 1 == steps_ && end_slope_ < want) {
    slope(steps_ * h_, y_[steps_], S_[steps_], derivatives, f_[steps_], df_[steps_]);
    end_slope_ = want;
  }
  const double t = rest / h_, t2 = t * t, t3 = t2 * t;
  const double c0 = 2 * t3 - 3 * t2 + 1, c1 = (t3 - 2 * t2 + t) * h_, c2 = 3 * t2 - 2 * t3,
               c3 = (t3 - t2) * h_;
  y_part_ = c0 * y_[node] + c1 * f_[node] + c2 * y_[node + 1] + c3 * f_[node + 1];
  if (derivatives) {
    S_part_ = c0 * S_[node] + c1 * df_[node] + c2 * S_[node + 1] + c3 * df_[node + 1];
  }
}

void IntervalInterpolant::rk4_step(double s, double len, const Eigen::VectorXd& y,
                                   const Eigen::MatrixXd& S, bool derivatives, Eigen::VectorXd& y1,
                                   Eigen::MatrixXd& S1) {
  // Forward-mode RK4: each stage's slope ẏ = [q̇_u; q̈_u] and its total derivative dẏ/dz.
  const double c[4] = {0, 0.5, 0.5, 1};
  for (int i = 0; i < 4; ++i) {
    if (i == 0) {
      ys_ = y;
      if (derivatives) Ss_ = S;
    } else {
      ys_ = y + c[i] * len * k_[i - 1];
      if (derivatives) Ss_ = S + c[i] * len * dk_[i - 1];
    }
    slope(s + c[i] * len, ys_, Ss_, derivatives, k_[i], dk_[i]);
  }
  y1 = y + len / 6 * (k_[0] + 2 * k_[1] + 2 * k_[2] + k_[3]);
  if (derivatives) S1 = S + len / 6 * (dk_[0] + 2 * dk_[1] + 2 * dk_[2] + dk_[3]);
}

void IntervalInterpolant::start(const Eigen::Ref<const Eigen::VectorXd>& q0,
                                const Eigen::Ref<const Eigen::VectorXd>& qd0,
                                const Eigen::Ref<const Eigen::VectorXd>& qdd0,
                                const Eigen::Ref<const Eigen::VectorXd>& qdd1, double dt,
                                bool derivatives) {
  const int n = model_.nq(), m = static_cast<int>(unactuated_.size());
  if (q0.size() != n || qd0.size() != n || qdd0.size() != n || qdd1.size() != n) {
    throw std::invalid_argument("interpolant: knot vectors must have one entry per joint");
  }
  if (!(dt > 0)) throw std::invalid_argument("interpolant: the interval must have dt > 0");
  q0_ = q0;
  qd0_ = qd0;
  qdd0_ = qdd0;
  qdd1_ = qdd1;
  dt_ = dt;
  derivatives_ = derivatives;
  steps_ = integration_steps(dt, max_step_);
  h_ = dt / steps_;
  if (m == 0) return;
  // Grow-only node storage: intervals of one plan share their step count.
  if (static_cast<int>(y_.size()) < steps_ + 1) {
    y_.resize(steps_ + 1, Eigen::VectorXd(2 * m));
    S_.resize(steps_ + 1, Eigen::MatrixXd(2 * m, 4 * n));
    if (coarse_) {
      f_.resize(steps_ + 1, Eigen::VectorXd(2 * m));
      df_.resize(steps_ + 1, Eigen::MatrixXd(2 * m, 4 * n));
    }
  }
  end_slope_ = 0;
  for (int i = 0; i < m; ++i) {
    y_[0][i] = q0[unactuated_[i]];
    y_[0][m + i] = qd0[unactuated_[i]];
  }
  if (derivatives) {
    S_[0].setZero();
    for (int i = 0; i < m; ++i) {
      S_[0](i, unactuated_[i]) = 1;
      S_[0](m + i, n + unactuated_[i]) = 1;
    }
  }
  for (int node = 0; node < steps_; ++node) {
    rk4_step(node * h_, h_, y_[node], S_[node], derivatives, y_[node + 1], S_[node + 1]);
    if (!coarse_) continue;
    f_[node] = k_[0];  // the first stage's slope is the node's
    if (derivatives) df_[node] = dk_[0];
  }
}

void IntervalInterpolant::at(double s, bool derivatives, InterpolantPoint& p, bool with_tau) {
  const double tiny = 1e-12 * dt_;
  if (!(s >= -tiny && s <= dt_ + tiny)) {
    throw std::invalid_argument("interpolant: sample time outside [0, dt]");
  }
  if (derivatives && !derivatives_) {
    throw std::invalid_argument("interpolant: derivatives asked of an interval started without");
  }
  if (unactuated_.empty()) {
    point(s, y_part_, S_part_, derivatives, with_tau, p);
    return;
  }
  // The node at or before s; a time on a node reads it, others take a partial step from it.
  const int node = std::min(steps_, static_cast<int>(std::floor((s + tiny) / h_)));
  const double rest = s - node * h_;
  if (rest <= tiny) {
    point(node * h_, y_[node], S_[node], derivatives, with_tau, p);
    return;
  }
  if (coarse_) {
    hermite(node, rest, derivatives);
  } else {
    rk4_step(node * h_, rest, y_[node], S_[node], derivatives, y_part_, S_part_);
  }
  point(s, y_part_, S_part_, derivatives, with_tau, p);
}

void IntervalInterpolant::evaluate(const Eigen::Ref<const Eigen::VectorXd>& q0,
                                   const Eigen::Ref<const Eigen::VectorXd>& qd0,
                                   const Eigen::Ref<const Eigen::VectorXd>& qdd0,
                                   const Eigen::Ref<const Eigen::VectorXd>& qdd1, double dt,
                                   const std::vector<double>& s, bool derivatives,
                                   std::vector<InterpolantPoint>& out) {
  start(q0, qd0, qdd0, qdd1, dt, derivatives);
  out.resize(s.size());
  for (size_t i = 0; i < s.size(); ++i) {
    if (i > 0 && s[i] < s[i - 1]) {
      throw std::invalid_argument("interpolant: sample times must ascend within [0, dt]");
    }
    at(s[i], derivatives, out[i]);
  }
}

}  // namespace kinograph::planning

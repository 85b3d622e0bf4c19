// The plan's interpolant and the between-knot factor: the cubic of the actuated joints, the
// unactuated joints following the dynamics (checked by inverse dynamics on numerically
// differentiated samples and by executing the plan's own torques through forward dynamics),
// and the IntervalDynamicsFactor's Jacobians against central differences.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/graph/testing/numerical_jacobian.h"
#include "kinograph/planning/factors/interval_factors.h"
#include "kinograph/planning/factors/trajectory_factors.h"
#include "kinograph/planning/interpolant.h"
#include "kinograph/planning/trajectory_sampler.h"
#include "listed_rows.h"
#include "test_problems.h"

namespace kinograph::planning {
namespace {

using graph::testing::check_jacobians;
using testing::load_robot;

// A random interval: knot k, accelerations at both ends, and knot k+1 from the collocation
// (so the actuated joints' cubic meets it); the unactuated joints' k+1 values are random.
graph::Values random_interval(int n, double dt, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  const auto rnd = [&] {
    Eigen::VectorXd v(n);
    for (int j = 0; j < n; ++j) v[j] = u(rng);
    return v;
  };
  const Eigen::VectorXd q0 = rnd(), v0 = rnd(), a0 = rnd(), a1 = rnd();
  graph::Values x;
  x.insert(q_key(0), q0);
  x.insert(v_key(0), v0);
  x.insert(a_key(0), a0);
  x.insert(q_key(1), Eigen::VectorXd(q0 + dt * v0 + dt * dt / 6 * (2 * a0 + a1)));
  x.insert(v_key(1), Eigen::VectorXd(v0 + dt / 2 * (a0 + a1)));
  x.insert(a_key(1), a1);
  return x;
}

// The turning instants are where the cubic's q̇ and q̈ vanish: checked against the cubic
// itself, and none outside (0, Δt).
TEST(Interpolant, ActuatedTurningTimesAreWhereTheCubicTurns) {
  const double dt = 0.5;
  const auto qd = [&](double qd0, double a0, double a1, double s) {
    return qd0 + a0 * s + (a1 - a0) * s * s / (2 * dt);
  };
  const auto qdd = [&](double a0, double a1, double s) { return a0 + (a1 - a0) * s / dt; };
  struct Case {
    double qd0, a0, a1;
    size_t count;
  } cases[] = {{1, -4, -4, 1},    // constant q̈: q turns once, at 0.25 s
               {1, -8, 6, 3},     // q̈ crosses zero, q̇ twice
               {1, 2, 3, 0},      // speeding up: no turn
               {0.1, 2, -30, 2},  // q̈ and one zero of q̇ inside, the other before 0
               {-0.5, 0, 0, 0}};  // constant q̇
  for (const Case& c : cases) {
    std::vector<double> s;
    actuated_turning_times(c.qd0, c.a0, c.a1, dt, s);
    EXPECT_EQ(s.size(), c.count) << c.qd0 << " " << c.a0 << " " << c.a1;
    for (double t : s) {
      EXPECT_GT(t, 0);
      EXPECT_LT(t, dt);
      EXPECT_TRUE(std::abs(qd(c.qd0, c.a0, c.a1, t)) < 1e-12 ||
                  std::abs(qdd(c.a0, c.a1, t)) < 1e-12)
          << t;
    }
  }
}

TEST(Interpolant, IntegrationStepsFollowTheLongestStep) {
  EXPECT_EQ(integration_steps(0.1), 10);
  EXPECT_EQ(integration_steps(0.2), 20);
  EXPECT_EQ(integration_steps(0.025), 3);
  EXPECT_EQ(integration_steps(1e-4), 1);
  EXPECT_EQ(integration_steps(0.1, 0.05), 2);  // the batch planner's warm-up step
  EXPECT_EQ(integration_steps(0.025, 0.05), 1);
}

TEST(Interpolant, FullyActuatedIsTheCollocationCubic) {
  const auto model = load_robot("robots/rr/rr.urdf");
  std::mt19937 rng(3);
  const double dt = 0.1;
  const graph::Values x = random_interval(2, dt, rng);
  IntervalInterpolant interp(*model);
  std::vector<InterpolantPoint> p;
  interp.evaluate(x.at(q_key(0)), x.at(v_key(0)), x.at(a_key(0)), x.at(a_key(1)), dt,
                  {0.0, 0.03, dt}, false, p);
  EXPECT_LT((p[0].q - x.at(q_key(0))).norm(), 1e-14);
  EXPECT_LT((p[2].q - x.at(q_key(1))).norm(), 1e-12);
  EXPECT_LT((p[2].qd - x.at(v_key(1))).norm(), 1e-12);
  EXPECT_LT((p[2].qdd - x.at(a_key(1))).norm(), 1e-12);
  // q̈ is linear between the knots; τ is the computed torque there.
  const Eigen::VectorXd a = 0.7 * x.at(a_key(0)) + 0.3 * x.at(a_key(1));
  EXPECT_LT((p[1].qdd - a).norm(), 1e-12);
  dynamics::Data data(*model);
  EXPECT_LT((p[1].tau - dynamics::rnea(*model, data, p[1].q, p[1].qd, p[1].qdd)).norm(), 1e-12);
}

// Samples a plan's interpolant on a fine grid inside every interval, takes q̇ and q̈ by central
// differences of the sampled q alone, and returns the worst |τ_u| by RNEA: independent of the
// interpolant's own q̇, q̈.
double worst_unactuated_torque_numeric(const dynamics::Model& model, const Plan& plan) {
  TrajectorySampler sampler(model, plan);
  dynamics::Data data(model);
  double worst = 0;
  for (int k = 0; k < sampler.intervals(); ++k) {
    const double dt = sampler.interval_length(k), e = dt / 200;
    for (int i = 0; i < 10; ++i) {
      const double t = plan.t[k] + (i + 0.5) / 10 * dt;
      const Eigen::VectorXd qm = sampler.at(t - e).q, q0 = sampler.at(t).q,
                            qp = sampler.at(t + e).q;
      const Eigen::VectorXd qd = (qp - qm) / (2 * e), qdd = (qp - 2 * q0 + qm) / (e * e);
      const Eigen::VectorXd& tau = dynamics::rnea(model, data, q0, qd, qdd);
      for (int j = 0; j < model.nq(); ++j) {
        if (!model.bodies[j].actuated) worst = std::max(worst, std::abs(tau[j]));
      }
    }
  }
  return worst;
}

// A two-knot Acrobot plan whose knot 1 is where the interpolant arrives.
Plan consistent_acrobot_interval(const dynamics::Model& model, double dt, std::mt19937& rng) {
  const graph::Values x = random_interval(2, dt, rng);
  Plan plan;
  plan.t = {0.0, dt};
  plan.q.resize(2, 2);
  plan.qd.resize(2, 2);
  plan.qdd.resize(2, 2);
  plan.tau.setZero(2, 2);
  plan.q.row(0) = x.at(q_key(0)).transpose();
  plan.qd.row(0) = x.at(v_key(0)).transpose();
  plan.qdd.row(0) = x.at(a_key(0)).transpose();
  plan.qdd.row(1) = x.at(a_key(1)).transpose();
  IntervalInterpolant interp(model);
  std::vector<InterpolantPoint> p;
  interp.evaluate(plan.q.row(0).transpose(), plan.qd.row(0).transpose(),
                  plan.qdd.row(0).transpose(), plan.qdd.row(1).transpose(), dt, {dt}, false, p);
  plan.q.row(1) = p[0].q.transpose();
  plan.qd.row(1) = p[0].qd.transpose();
  return plan;
}

TEST(Interpolant, UnactuatedJointFollowsTheDynamics) {
  const auto model = testing::acrobot_model();
  ASSERT_FALSE(model->bodies[0].actuated);
  std::mt19937 rng(5);
  for (int trial = 0; trial < 5; ++trial) {
    const Plan plan = consistent_acrobot_interval(*model, 0.1, rng);
    EXPECT_LT(worst_unactuated_torque_numeric(*model, plan), 1e-3) << "trial " << trial;
  }
}

TEST(Interpolant, ComputedTorqueExecutesThePlan) {
  // The executor's contract: apply τ_a(t) of the interpolant, nothing on the shoulder, and the
  // true Acrobot (forward dynamics, fine RK4) stays on the interpolant.
  const auto model = testing::acrobot_model();
  std::mt19937 rng(11);
  const double dt = 0.2;
  const Plan plan = consistent_acrobot_interval(*model, dt, rng);
  TrajectorySampler sampler(*model, plan);
  dynamics::Data data(*model);
  const auto f = [&](double t, const Eigen::VectorXd& x) {
    Eigen::VectorXd tau = sampler.at(t).tau;
    tau[0] = 0;
    Eigen::VectorXd dx(4);
    dx << x.tail(2), dynamics::forward_dynamics(*model, data, x.head(2), x.tail(2), tau);
    return dx;
  };
  Eigen::VectorXd x(4);
  x << plan.q.row(0).transpose(), plan.qd.row(0).transpose();
  const int steps = 2000;
  const double h = dt / steps;
  double worst = 0;
  for (int i = 0; i < steps; ++i) {
    const double t = i * h;
    const Eigen::VectorXd k1 = f(t, x), k2 = f(t + h / 2, x + h / 2 * k1),
                          k3 = f(t + h / 2, x + h / 2 * k2), k4 = f(t + h, x + h * k3);
    x += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    const InterpolantPoint p = sampler.at(std::min(t + h, dt - 1e-12));
    worst = std::max(worst, (x.head(2) - p.q).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(Interpolant, SamplerRefusesPlansThatDoNotFit) {
  const auto model = testing::acrobot_model();
  std::mt19937 rng(1);
  Plan plan = consistent_acrobot_interval(*model, 0.1, rng);
  plan.t = {0.0, 0.0};
  EXPECT_THROW(TrajectorySampler(*model, plan), std::invalid_argument);
  plan.t = {0.0, 0.1};
  plan.qd.resize(2, 3);
  EXPECT_THROW(TrajectorySampler(*model, plan), std::invalid_argument);
}

// The factor's raw rows z (compute(), not the hinged residual, which is zero for rows inside
// their bounds) as a factor of their own, so their Jacobians are checked against central
// differences row by row.
class RawRows final : public graph::Factor {
 public:
  explicit RawRows(const ConstrainedFactor& f)
      : graph::Factor(f.keys(), f.dims(), f.residual_dim()), f_(f) {}
  void evaluate(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const graph::Jacobians* J) const override {
    f_.compute(x, e, J);
  }

 private:
  const ConstrainedFactor& f_;
};

// A random interval with the unactuated joints' knot k+1 moved off the defect's zero.
graph::Values off_defect_interval(int n, double dt, std::mt19937& rng) {
  graph::Values x = random_interval(n, dt, rng);
  x.update(q_key(1), Eigen::VectorXd(x.at(q_key(1)) + Eigen::VectorXd::Constant(n, 0.05)));
  return x;
}

void expect_raw_jacobians(std::shared_ptr<const dynamics::Model> model, int checks,
                          unsigned seed, double integration_step = kMaxIntegrationStep,
                          int limit_rows = kAllLimitRows) {
  IntervalDynamicsOptions o;
  o.checks = checks;
  o.integration_step = integration_step;
  o.limit_rows = limit_rows;
  const double dt = 0.1;
  IntervalDynamicsFactor f(0, dt, model, o);
  std::mt19937 rng(seed);
  for (int trial = 0; trial < 3; ++trial) {
    const graph::Values x = off_defect_interval(model->nq(), dt, rng);
    graph::testing::JacobianCheckOptions c;
    c.tolerance = 1e-6;
    const auto check = check_jacobians(RawRows(f), x, c);
    EXPECT_TRUE(check.ok) << model->name << " trial " << trial << "\n" << check.report();
  }
}

TEST(IntervalDynamicsFactor, JacobiansUnderactuated) {
  expect_raw_jacobians(testing::acrobot_model(), 3, 21);
}
// The batch planner's warm-up rows: two RK4 steps per interval, check points between the nodes
// (read from the Hermite of the two nodes).
TEST(IntervalDynamicsFactor, JacobiansWithTheWarmUpStep) {
  expect_raw_jacobians(testing::acrobot_model(), 4, 23, 0.05);
}
TEST(IntervalDynamicsFactor, JacobiansFullyActuated) {
  expect_raw_jacobians(load_robot("robots/rr/rr.urdf"), 2, 22);
}
// One kind of limit rows only (IntervalLimitRows): without the torque rows a fully actuated
// arm's points skip the dynamics altogether.
TEST(IntervalDynamicsFactor, JacobiansWithOneKindOfLimitRows) {
  for (int bits : {kMotionLimitRows, kEffortLimitRows}) {
    expect_raw_jacobians(testing::acrobot_model(), 3, 24, kMaxIntegrationStep, bits);
    expect_raw_jacobians(load_robot("robots/rr/rr.urdf"), 2, 25, kMaxIntegrationStep, bits);
  }
}

// Each kind's rows alone read what the same rows read beside all the others, and are the ones
// its bit names: the torque rows for kEffortLimitRows, the q and q̇ rows for kMotionLimitRows.
TEST(IntervalDynamicsFactor, LimitRowsByKindReadTheSameValues) {
  using Kind = IntervalDynamicsFactor::Row::Kind;
  for (const auto& model : {testing::acrobot_model(), load_robot("robots/rr/rr.urdf")}) {
    IntervalDynamicsOptions all;
    all.checks = 3;
    std::mt19937 rng(41);
    const graph::Values x = off_defect_interval(model->nq(), 0.1, rng);
    Eigen::VectorXd z_all;
    IntervalDynamicsFactor(0, 0.1, model, all).values_at(x, z_all);
    const auto all_rows = IntervalDynamicsFactor::layout(*model, all);
    for (int bits : {kNoLimitRows, kMotionLimitRows, kEffortLimitRows}) {
      IntervalDynamicsOptions o = all;
      o.limit_rows = bits;
      const auto rows = IntervalDynamicsFactor::layout(*model, o);
      if (rows.empty()) {  // a fully actuated arm without limit rows has no rows at all
        EXPECT_EQ(bits, kNoLimitRows) << model->name;
        EXPECT_THROW(IntervalDynamicsFactor(0, 0.1, model, o), std::invalid_argument);
        continue;
      }
      Eigen::VectorXd z;
      IntervalDynamicsFactor(0, 0.1, model, o).values_at(x, z);
      ASSERT_EQ(z.size(), static_cast<Eigen::Index>(rows.size()));
      size_t j = 0;  // the same row among all of them (both layouts in the same order)
      for (size_t i = 0; i < rows.size(); ++i) {
        const auto& r = rows[i];
        while (j < all_rows.size() && (all_rows[j].kind != r.kind ||
                                       all_rows[j].joint != r.joint ||
                                       all_rows[j].point != r.point)) {
          ++j;
        }
        ASSERT_LT(j, all_rows.size()) << model->name << " bits " << bits << " row " << i;
        EXPECT_EQ(z[i], z_all[j]) << model->name << " bits " << bits << " row " << i;
        const bool defect = r.kind == Kind::kDefectQ || r.kind == Kind::kDefectQd;
        if (!defect) {
          EXPECT_EQ(r.kind == Kind::kTau, bits == kEffortLimitRows) << model->name << " " << i;
        }
      }
      const auto limit_rows = std::count_if(rows.begin(), rows.end(), [](const auto& r) {
        return r.point >= 0;
      });
      EXPECT_EQ(limit_rows == 0, bits == kNoLimitRows) << model->name << " bits " << bits;
    }
  }
}

// A fully actuated arm's factor with q and q̇ rows only lists the rows it writes, so J arrives
// unzeroed (filled with NaN here): its listed rows and residual must equal an evaluation into a
// zeroed J, with rows kept on by a multiplier although inside their bounds, rows past a limit
// (fast knots), and intervals where every row is clear (none listed). A factor with torque
// rows keeps its Jacobian instead and gets J zeroed.
TEST(IntervalDynamicsFactor, MotionRowsListedEqualAZeroedEvaluation) {
  const auto model = load_robot("robots/iiwa14/iiwa14.urdf");
  const int n = model->nq();
  IntervalDynamicsOptions o;
  o.checks = 9;
  o.limit_rows = kMotionLimitRows;
  o.limit_epsilon = 0.03;
  const double dt = 0.1;
  EXPECT_FALSE(IntervalDynamicsFactor(0, dt, model, [&] {
                 IntervalDynamicsOptions all = o;
                 all.limit_rows = kAllLimitRows;
                 return all;
               }()).writes_listed_rows_only());
  std::mt19937 rng(31);
  int listed = 0, kept_on = 0, clear = 0;
  for (int trial = 0; trial < 48; ++trial) {
    graph::Values x = random_interval(n, dt, rng);
    const double speed = 0.5 * (1 + trial % 4);  // up to 2 rad/s: past joint 1's 1.48 limit
    x.update(v_key(0), Eigen::VectorXd(speed * x.at(v_key(0))));
    IntervalDynamicsFactor f(0, dt, model, o);
    EXPECT_TRUE(f.writes_listed_rows_only());
    auto m = std::make_shared<Multipliers>(f.residual_dim(), 10.0);
    if (trial % 2 == 1) {
      for (int i = 0; i < f.residual_dim(); i += 7) m->upper[i] = 50.0;
    }
    f.bind(m);
    const testing::Linearization whole = testing::linearize(f, x, 0.0, false);
    const testing::Linearization part =
        testing::linearize(f, x, std::numeric_limits<double>::quiet_NaN(), true);
    EXPECT_EQ(part.r, whole.r) << "trial " << trial;
    const std::vector<int> rows = part.support.all ? std::vector<int>() : part.support.rows;
    if (!part.support.all && rows.empty()) {
      ++clear;
      EXPECT_TRUE(whole.r.isZero() && whole.J.isZero()) << "trial " << trial;
    }
    for (int i = 0; i < f.residual_dim(); ++i) {
      if (!part.support.all && !std::binary_search(rows.begin(), rows.end(), i)) {
        EXPECT_TRUE(whole.J.row(i).isZero()) << "trial " << trial << " row " << i;
        continue;
      }
      ++listed;
      EXPECT_EQ(part.J.row(i), whole.J.row(i)) << "trial " << trial << " row " << i;
      kept_on += whole.r[i] != 0 && m->upper[i] > 0 ? 1 : 0;
    }
  }
  EXPECT_GT(listed, 100);
  EXPECT_GT(kept_on, 20);
  EXPECT_GT(clear, 5);
}

// The factor's hinged residual Jacobian at x against central differences.
void expect_exact_linearization(const ConstrainedFactor& f, const graph::Values& x,
                                const std::string& what = "") {
  graph::testing::JacobianCheckOptions c;
  c.tolerance = 1e-6;
  const auto check = check_jacobians(f, x, c);
  EXPECT_TRUE(check.ok) << what << "\n" << check.report();
}

// An interval factor with five check points (Δt = 0.1 s) at a random interval x, its raw
// values z, and multipliers (μ = 4, every λ zero) to turn rows on with.
struct FiveCheckInterval {
  FiveCheckInterval(std::shared_ptr<const dynamics::Model> model, unsigned seed, bool off_defect)
      : f(0, 0.1, model, [] {
          IntervalDynamicsOptions o;
          o.checks = 5;
          return o;
        }()) {
    std::mt19937 rng(seed);
    x = off_defect ? off_defect_interval(model->nq(), 0.1, rng)
                   : random_interval(model->nq(), 0.1, rng);
    f.values_at(x, z);
    m = std::make_shared<Multipliers>(f.residual_dim(), 4.0);
  }
  IntervalDynamicsFactor f;
  graph::Values x;
  Eigen::VectorXd z;
  std::shared_ptr<Multipliers> m;
};

// While linearizing, the factor skips the derivatives of check points whose rows are all off.
// The hinged residual's Jacobian must still be exact: rows violated, rows inside their bound
// but kept on by a multiplier, and rows off, against central differences of the residual.
TEST(IntervalDynamicsFactor, LinearizationIsExactWithRowsOnAndOff) {
  for (const auto& robot : {testing::acrobot_model(), load_robot("robots/rr/rr.urdf")}) {
    auto model = std::make_shared<dynamics::Model>(*robot);
    const std::string& urdf = model->name;
    for (dynamics::Body& b : model->bodies) b.limits.effort = std::min(b.limits.effort, 0.5);
    FiveCheckInterval t(model, 31, true);
    IntervalDynamicsFactor& f = t.f;
    const Eigen::VectorXd& z = t.z;
    Multipliers* m = t.m.get();
    int on = 0, off = 0, kept_on = 0;
    for (int i = 0; i < f.residual_dim(); ++i) {
      const RowSpec& r = f.rows()[i];
      if (r.kind != RowKind::kBounds) continue;
      const bool violated = z[i] > r.upper || z[i] < r.lower;
      if (!violated && off % 2 == 0) {
        m->upper[i] = 50.0;  // inside its bound, but on through its multiplier
        ++kept_on;
      }
      (violated ? on : off) += 1;
    }
    f.bind(t.m);
    ASSERT_GT(on, 0) << urdf;
    ASSERT_GT(off, kept_on) << urdf;
    ASSERT_GT(kept_on, 0) << urdf;
    expect_exact_linearization(f, t.x, urdf);
  }
}

// A fully actuated arm whose check points have position and velocity rows on but every torque
// row off: their Jacobian rows come from the cubic alone, without the dynamics' derivatives.
TEST(IntervalDynamicsFactor, LinearizationIsExactWithOnlyMotionRowsOn) {
  FiveCheckInterval t(load_robot("robots/rr/rr.urdf"), 33, false);
  int motion_on = 0;
  for (int i = 0; i < t.f.residual_dim(); ++i) {
    const RowSpec& row = t.f.rows()[i];
    ASSERT_EQ(row.kind, RowKind::kBounds);
    const bool torque = row.scale == IntervalDynamicsOptions().torque_scale;
    ASSERT_TRUE(t.z[i] <= row.upper && t.z[i] >= row.lower) << "row " << i;
    if (torque || i % 3 == 0) continue;  // torque rows and some motion rows stay off
    t.m->upper[i] = t.m->penalty * (row.upper - t.z[i]) / row.scale + 1;  // on through λ
    ++motion_on;
  }
  ASSERT_GT(motion_on, 0);
  t.f.bind(t.m);
  expect_exact_linearization(t.f, t.x);
}

// The factor keeps its last evaluation while the variables stay the same; a bound row whose
// hinge was off then (its Jacobian row left unfilled) and is on now must not be read from it.
TEST(IntervalDynamicsFactor, KeptEvaluationIsExactWhenRowsTurnOn) {
  auto model = std::make_shared<dynamics::Model>(*testing::acrobot_model());
  for (dynamics::Body& b : model->bodies) b.limits.effort = std::min(b.limits.effort, 0.5);
  IntervalDynamicsOptions o;
  o.checks = 5;
  IntervalDynamicsFactor f(0, 0.1, model, o);
  std::mt19937 rng(32);
  const graph::Values x = off_defect_interval(model->nq(), 0.1, rng);
  f.bind(std::make_shared<Multipliers>(f.residual_dim(), 4.0));
  Eigen::VectorXd r, z;
  Eigen::MatrixXd J;
  f.linearize(x, r, J);  // kept, with the rows inside their bounds off
  f.values_at(x, z);
  auto on = std::make_shared<Multipliers>(f.residual_dim(), 4.0);
  int turned_on = 0;
  for (int i = 0; i < f.residual_dim(); ++i) {
    const RowSpec& row = f.rows()[i];
    if (row.kind != RowKind::kBounds || z[i] > row.upper || z[i] < row.lower) continue;
    // On through its multiplier: √μ (z − upper)/s + λ/√μ = 1/√μ > 0.
    on->upper[i] = on->penalty * (row.upper - z[i]) / row.scale + 1;
    ++turned_on;
  }
  ASSERT_GT(turned_on, 0);
  f.bind(on);
  expect_exact_linearization(f, x);
}

// The interval factors of a graph share one scratch per worker: each evaluation must equal
// that of a factor with its own, whatever the factors evaluated before it on that scratch
// (more or fewer check points, other values, with or without Jacobians).
TEST(IntervalDynamicsFactor, FactorsSharingAWorkspaceEvaluateAsAlone) {
  const auto model = testing::acrobot_model();
  const double step = 0.05;
  auto shared = std::make_shared<IntervalWorkspace>(model, step);
  std::vector<IntervalDynamicsFactor> together, alone;
  for (int checks : {5, 0, 3}) {
    IntervalDynamicsOptions o;
    o.checks = checks;
    o.integration_step = step;
    together.emplace_back(0, 0.1, model, o, shared);
    alone.emplace_back(0, 0.1, model, o);
  }
  std::mt19937 rng(51);
  for (int trial = 0; trial < 12; ++trial) {
    const size_t i = static_cast<size_t>(trial) % together.size();
    const graph::Values x = off_defect_interval(model->nq(), 0.1, rng);
    Eigen::VectorXd r1, r2, z1, z2;
    Eigen::MatrixXd J1, J2;
    together[i].linearize(x, r1, J1);
    alone[i].linearize(x, r2, J2);
    EXPECT_EQ(r1, r2) << "factor " << i << " trial " << trial;
    EXPECT_EQ(J1, J2) << "factor " << i << " trial " << trial;
    const graph::Values y = off_defect_interval(model->nq(), 0.1, rng);
    together[i].values_at(y, z1);
    alone[i].values_at(y, z2);
    EXPECT_EQ(z1, z2) << "factor " << i << " trial " << trial;
  }
  // A workspace is for one model and RK4 step.
  IntervalDynamicsOptions o;
  o.checks = 2;
  EXPECT_THROW(IntervalDynamicsFactor(0, 0.1, model, o, shared), std::invalid_argument);
  o.integration_step = step;
  EXPECT_THROW(IntervalDynamicsFactor(0, 0.1, load_robot("robots/rr/rr.urdf"), o, shared),
               std::invalid_argument);
}

TEST(IntervalDynamicsFactor, RowsOfTheAcrobot) {
  const auto model = testing::acrobot_model();
  IntervalDynamicsOptions o;
  o.checks = 4;
  // 2 defect rows; per point the elbow's τ, both q and both q̇ limits.
  EXPECT_EQ(IntervalDynamicsFactor(0, 0.1, model, o).residual_dim(), 2 + 4 * 5);
  o.checks = 0;
  EXPECT_EQ(IntervalDynamicsFactor(0, 0.1, model, o).residual_dim(), 2);
  const auto rr = load_robot("robots/rr/rr.urdf");
  EXPECT_THROW(IntervalDynamicsFactor(0, 0.1, rr, o), std::invalid_argument);
}

// Rows in the user's terms: the defect as the unactuated joint missing the next knot, a limit
// row at its check point's own time.
TEST(IntervalDynamicsFactor, RowsSpeakUserTerms) {
  const auto model = testing::acrobot_model();
  IntervalDynamicsOptions o;
  o.checks = 4;
  IntervalDynamicsFactor f(55, 0.1, model, o);
  const auto context = [&](double violation) {
    return ConstrainedFactor::RowContext{*model, 5.5, 0.1, "dynamics between the knots", -1,
                                         violation};
  };
  EXPECT_EQ(f.describe_row(0, 0.02, context(0.02)),
            "joint 1 (shoulder), unactuated, follows its dynamics from t = 5.5 s and arrives at "
            "t = 5.6 s 0.02 rad off the next knot's position");
  EXPECT_EQ(f.describe_row(1, -0.3, context(0.3)),
            "joint 1 (shoulder), unactuated, follows its dynamics from t = 5.5 s and arrives at "
            "t = 5.6 s 0.3 rad/s off the next knot's velocity");
  // Rows of check point 1 (t = 5.5 + 2·0.1/5 s): shoulder q, q̇, then the elbow's τ first.
  int tau_row = -1;
  for (int i = 0; i < f.residual_dim(); ++i) {
    if (tau_row < 0 && f.rows()[i].upper == 8.0) tau_row = i;
  }
  ASSERT_GE(tau_row, 0);
  const int per_point = 5;  // elbow τ, both q and both q̇
  EXPECT_EQ(f.describe_row(tau_row + per_point, 8.6, context(0.6)),
            "joint 2 (elbow) torque 8.6 N·m exceeds its 8 N·m limit by 0.6 N·m at t = 5.54 s "
            "(between the knots)");
}

TEST(IntervalDynamicsFactor, DefectIsZeroOnTheInterpolant) {
  const auto model = testing::acrobot_model();
  std::mt19937 rng(8);
  const Plan plan = consistent_acrobot_interval(*model, 0.1, rng);
  graph::Values x;
  for (int k = 0; k < 2; ++k) {
    x.insert(q_key(k), Eigen::VectorXd(plan.q.row(k).transpose()));
    x.insert(v_key(k), Eigen::VectorXd(plan.qd.row(k).transpose()));
    x.insert(a_key(k), Eigen::VectorXd(plan.qdd.row(k).transpose()));
  }
  IntervalDynamicsFactor f(0, 0.1, model, {});
  Eigen::VectorXd z;
  f.values_at(x, z);
  EXPECT_LT(z.cwiseAbs().maxCoeff(), 1e-12);
  x.update(v_key(1), Eigen::VectorXd(x.at(v_key(1)) + Eigen::Vector2d(0.01, 0)));
  f.values_at(x, z);
  EXPECT_NEAR(z[1], 0.01, 1e-12);  // the shoulder's q̇ defect
}

}  // namespace
}  // namespace kinograph::planning

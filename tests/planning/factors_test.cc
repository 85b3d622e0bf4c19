// Jacobians of every planning factor against central differences, the GP covariance against a
// numerical integral, collocation consistency, and the augmented-Lagrangian row algebra.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <random>
#include <unsupported/Eigen/MatrixFunctions>

#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/payload.h"
#include "kinograph/graph/testing/numerical_jacobian.h"
#include "kinograph/planning/factors/collision_factors.h"
#include "kinograph/planning/factors/dynamics_factors.h"
#include "kinograph/planning/factors/pose_factors.h"
#include "kinograph/planning/factors/state_target_factor.h"
#include "kinograph/planning/factors/trajectory_factors.h"
#include "test_problems.h"

namespace kinograph::planning {
namespace {

using graph::testing::check_jacobians;

// Binds `f` to its own multipliers record at penalty μ (zero multipliers unless given).
void bind(ConstrainedFactor& f, double mu, const Eigen::VectorXd& lower = {},
          const Eigen::VectorXd& upper = {}) {
  auto m = std::make_shared<Multipliers>(f.residual_dim(), mu);
  if (lower.size() > 0) m->lower = lower;
  if (upper.size() > 0) m->upper = upper;
  f.bind(m);
}
using graph::testing::JacobianCheckOptions;

std::shared_ptr<const dynamics::Model> load(const std::string& rel) {
  return std::make_shared<const dynamics::Model>(
      dynamics::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) + "/" + rel));
}

// Random q, q̇, q̈ for states 0..steps.
graph::Values random_states(int n, int steps, std::mt19937& rng, double scale = 1.0) {
  std::uniform_real_distribution<double> u(-scale, scale);
  graph::Values v;
  for (int k = 0; k <= steps; ++k) {
    Eigen::VectorXd q(n), qd(n), qdd(n);
    for (int j = 0; j < n; ++j) {
      q[j] = u(rng);
      qd[j] = u(rng);
      qdd[j] = u(rng);
    }
    v.insert(q_key(k), q);
    v.insert(v_key(k), qd);
    v.insert(a_key(k), qdd);
  }
  return v;
}

TEST(GpPrior, CovarianceIsTheIntegralOfTheWhiteNoiseJerkModel) {
  // Q = ∫₀^Δt e^{As} L Qc Lᵀ e^{Aᵀs} ds by Simpson's rule on the matrix exponential.
  Eigen::Matrix3d A;
  A << 0, 1, 0, 0, 0, 1, 0, 0, 0;
  const Eigen::Vector3d L(0, 0, 1);
  for (double dt : {0.1, 0.37, 1.3}) {
    const double qc = 2.5;
    const int m = 2000;
    Eigen::Matrix3d Q = Eigen::Matrix3d::Zero();
    for (int i = 0; i <= m; ++i) {
      const double s = dt * i / m;
      const double w = (i == 0 || i == m) ? 1 : (i % 2 == 1 ? 4 : 2);
      const Eigen::Matrix3d E = (A * s).exp();
      Q += w * E * L * qc * L.transpose() * E.transpose();
    }
    Q *= dt / (3 * m);
    EXPECT_TRUE(Q.isApprox(gp_covariance(dt, qc), 1e-9)) << Q << "\n" << gp_covariance(dt, qc);
    EXPECT_TRUE(gp_transition(dt).isApprox((A * dt).exp(), 1e-12));
    // The corner is Δt⁵/20, not the ½Δt⁵ printed in the paper.
    EXPECT_NEAR(gp_covariance(dt, 1.0)(0, 0), std::pow(dt, 5) / 20, 1e-15);
  }
}

TEST(GpPrior, CostUnderCollocationIsIntegratedSquaredJerk) {
  // A piecewise-linear acceleration satisfies the collocation exactly; its GP cost must be
  // ½·jerk²·Δt/Qc per joint and interval.
  const double dt = 0.2, qc = 0.7, jerk = 1.9;
  graph::Values v;
  const Eigen::VectorXd a0 = Eigen::VectorXd::Constant(1, 0.3);
  const Eigen::VectorXd a1 = a0.array() + jerk * dt;
  const Eigen::VectorXd q0 = Eigen::VectorXd::Constant(1, 0.1);
  const Eigen::VectorXd v0 = Eigen::VectorXd::Constant(1, -0.4);
  v.insert(q_key(0), q0);
  v.insert(v_key(0), v0);
  v.insert(a_key(0), a0);
  v.insert(q_key(1), q0 + v0 * dt + dt * dt / 6 * (2 * a0 + a1));
  v.insert(v_key(1), v0 + dt / 2 * (a0 + a1));
  v.insert(a_key(1), a1);
  CollocationFactor col(0, 1, dt);
  Eigen::VectorXd z;
  col.values_at(v, z);
  EXPECT_LT(z.cwiseAbs().maxCoeff(), 1e-15);
  GpPriorFactor gp(0, 1, dt, qc);
  EXPECT_NEAR(gp.error(v), 0.5 * jerk * jerk * dt / qc, 1e-9);
}

TEST(TrajectoryFactors, Jacobians) {
  std::mt19937 rng(1);
  const int n = 3;
  graph::Values v = random_states(n, 1, rng);
  GpPriorFactor gp(0, n, 0.1, 1.3);
  auto c = check_jacobians(gp, v);
  EXPECT_TRUE(c.ok) << c.report();
  CollocationFactor col(0, n, 0.1);
  bind(col, 7.0);
  c = check_jacobians(col, v, {1e-6, 1e-5, true});
  EXPECT_TRUE(c.ok) << c.report();
  c = check_jacobians(col, v);
  EXPECT_TRUE(c.ok) << c.report();
  // Limits with some rows active (beyond a bound) and some inactive, away from the kinks.
  std::vector<StateLimitFactor::Limit> limits = {
      {0, 0, -0.5, 0.5}, {1, 1, -2, 2}, {2, 2, -0.1, 0.1}, {0, 2, -3, 3}};
  StateLimitFactor lim(0, n, limits, 0.5);
  Eigen::VectorXd lam = Eigen::VectorXd::Zero(4), lam_u = Eigen::VectorXd::Zero(4);
  lam[3] = 0.2;
  bind(lim, 3, lam, lam_u);
  v.update(q_key(0), Eigen::Vector3d(0.8, 0.1, 0.2));
  v.update(a_key(0), Eigen::Vector3d(0.1, 0.1, -0.4));
  c = check_jacobians(lim, v, {1e-6, 1e-5, true});
  EXPECT_TRUE(c.ok) << c.report();
  Eigen::VectorXd r(4);
  lim.whitened_residual(v, r);
  EXPECT_GT(std::abs(r[0]), 0);  // q0 = 0.8 above 0.5
  EXPECT_GT(std::abs(r[2]), 0);  // q̈2 = −0.4 below −0.1
  EXPECT_EQ(r[1], 0);            // q̇1 inside
  EXPECT_NEAR(lim.violation(v), 0.3, 1e-12);
}

// Factors that declare themselves linear (solvers keep their JᵀJ) have the same Jacobian at any
// two points, and a new version when the penalty or the noise model changes; hinges do not.
TEST(TrajectoryFactors, LinearFactorsHaveConstantJacobians) {
  std::mt19937 rng(3);
  const int n = 3;
  const graph::Values a = random_states(n, 1, rng, 2.0), b = random_states(n, 1, rng, 2.0);
  auto col = std::make_shared<CollocationFactor>(0, n, 0.1);
  bind(*col, 7.0);
  auto target = std::make_shared<StateTargetFactor>(std::vector<graph::Key>{q_key(1)}, n,
                                                    Eigen::Vector3d(0.1, 0.2, 0.3), 0.01);
  const std::vector<std::shared_ptr<graph::Factor>> linear = {
      std::make_shared<GpPriorFactor>(0, n, 0.1, 1.3), col, target,
      StateTargetFactor::soft({q_key(0), v_key(0)}, n, Eigen::VectorXd::Ones(2 * n), 1e3)};
  for (const auto& f : linear) {
    EXPECT_GE(f->jacobian_version(), 0) << f->name();
    Eigen::VectorXd ra, rb;
    Eigen::MatrixXd Ja, Jb;
    f->linearize(a, ra, Ja);
    f->linearize(b, rb, Jb);
    EXPECT_NE(ra, rb) << f->name();
    EXPECT_EQ(Ja, Jb) << f->name();
  }
  const long v = col->jacobian_version();
  bind(*col, 7.0);
  EXPECT_EQ(col->jacobian_version(), v);
  bind(*col, 70.0);
  EXPECT_NE(col->jacobian_version(), v);
  const long w = linear[0]->jacobian_version();
  linear[0]->set_noise(std::make_shared<graph::IsotropicNoise>(3 * n, 0.5));
  EXPECT_NE(linear[0]->jacobian_version(), w);
  // A hinge noise model makes even a linear factor's Jacobian depend on the point.
  linear[0]->set_noise(std::make_shared<graph::HingeNoise>(
      Eigen::VectorXd::Constant(3 * n, -1), Eigen::VectorXd::Constant(3 * n, 1), 0.1, 1.0));
  EXPECT_EQ(linear[0]->jacobian_version(), -1);
  StateLimitFactor lim(0, n, {{0, 0, -0.5, 0.5}});
  EXPECT_EQ(lim.jacobian_version(), -1);
}

TEST(ConstrainedFactor, MultiplierUpdateClipsInequalities) {
  std::mt19937 rng(2);
  graph::Values v = random_states(1, 0, rng);
  v.update(q_key(0), Eigen::VectorXd::Constant(1, 0.2));
  StateLimitFactor lim(0, 1, {{0, 0, -1, 1}});
  Multipliers m(1, 10);
  lim.update_multipliers(v, m);  // inside: multipliers stay 0
  EXPECT_EQ(m.lower[0], 0);
  EXPECT_EQ(m.upper[0], 0);
  v.update(q_key(0), Eigen::VectorXd::Constant(1, 1.5));
  lim.update_multipliers(v, m);
  EXPECT_NEAR(m.upper[0], 10 * 0.5, 1e-12);
  EXPECT_EQ(m.lower[0], 0);
}

// A bound row inside its bounds is off (zero residual and Jacobian) until a multiplier moves
// its hinge past the bound: r = −(√μ (z − u) + λ_u/√μ) when that is positive.
TEST(ConstrainedFactor, BoundRowInsideItsBoundsIsOnOnlyWhenAMultiplierPushes) {
  std::mt19937 rng(3);
  graph::Values v = random_states(1, 0, rng);
  v.update(q_key(0), Eigen::VectorXd::Constant(1, 0.9));
  StateLimitFactor lim(0, 1, {{0, 0, -1, 1}});
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  for (const double lambda_upper : {0.0, 5.0, 20.0}) {
    bind(lim, 100, Eigen::VectorXd::Zero(1), Eigen::VectorXd::Constant(1, lambda_upper));
    lim.linearize(v, r, J);
    const double b = 10 * (0.9 - 1) + lambda_upper / 10;  // -1, -0.5, 1
    EXPECT_DOUBLE_EQ(r[0], -std::max(0.0, b)) << "λ_u = " << lambda_upper;
    EXPECT_DOUBLE_EQ(J(0, 0), b > 0 ? -10.0 : 0.0) << "λ_u = " << lambda_upper;
  }
  bind(lim, 100, Eigen::VectorXd::Constant(1, 200.0), Eigen::VectorXd::Zero(1));
  lim.linearize(v, r, J);  // the lower multiplier pushes from the other side: a = −19 + 20
  EXPECT_NEAR(r[0], 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(J(0, 0), -10.0);
}

// z = q², counting its evaluations, with the evaluations kept (as the dynamics rows keep them)
// or only the values (as the collision rows). `unmeasured`: the row is the bound z ≥ 0.01 and
// compute() says it left its clear rows unmeasured (as the collision rows do for values alone).
class CountingFactor : public ConstrainedFactor {
 public:
  explicit CountingFactor(bool values_only = false, bool unmeasured = false)
      : ConstrainedFactor({q_key(0)}, {1},
                          {unmeasured ? RowSpec{RowKind::kBounds, 0.01, 1e9, 1, 1}
                                      : RowSpec{RowKind::kSoft, 0, 0, 1, 2}}),
        unmeasured_(unmeasured) {
    if (values_only) {
      cache_values();
    } else {
      cache_evaluations();
    }
  }
  void compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
               const graph::Jacobians* J) const override {
    ++calls;
    z[0] = x[0][0] * x[0][0];
    if (J != nullptr) J->block(0)(0, 0) = 2 * x[0][0];
    if (unmeasured_) clear_rows_not_measured();
  }
  mutable int calls = 0;

 private:
  bool unmeasured_;
};

TEST(ConstrainedFactor, ValuesAtTheLastLinearizationAreNotComputedAgain) {
  graph::Values v;
  v.insert(q_key(0), Eigen::VectorXd::Constant(1, 0.3));
  CountingFactor f;
  Eigen::VectorXd r, z;
  Eigen::MatrixXd J;
  f.linearize(v, r, J);
  EXPECT_EQ(f.calls, 1);
  f.values_at(v, z);  // the stopping rule's and the multiplier update's reading
  EXPECT_EQ(f.calls, 1);
  EXPECT_DOUBLE_EQ(z[0], 0.09);
  EXPECT_DOUBLE_EQ(f.terms(v).soft_cost, 0.5 * std::pow(2 * 0.09, 2));
  EXPECT_EQ(f.calls, 1);
  v.update(q_key(0), Eigen::VectorXd::Constant(1, 0.5));
  f.values_at(v, z);  // elsewhere: computed
  EXPECT_EQ(f.calls, 2);
  EXPECT_DOUBLE_EQ(z[0], 0.25);
  f.linearize(v, r, J);  // the Jacobian was never computed there
  EXPECT_EQ(f.calls, 3);
  EXPECT_DOUBLE_EQ(J(0, 0), 2 * 2 * 0.5);
}

TEST(ConstrainedFactor, KeptValuesServeOnlyValues) {
  graph::Values v;
  v.insert(q_key(0), Eigen::VectorXd::Constant(1, 0.3));
  CountingFactor f(/*values_only=*/true);
  Eigen::VectorXd r, z;
  Eigen::MatrixXd J;
  f.linearize(v, r, J);
  f.values_at(v, z);
  EXPECT_EQ(f.calls, 1);
  EXPECT_DOUBLE_EQ(z[0], 0.09);
  f.linearize(v, r, J);  // no Jacobian is kept
  EXPECT_EQ(f.calls, 2);
  v.update(q_key(0), Eigen::VectorXd::Constant(1, -0.4));
  f.values_at(v, z);
  f.values_at(v, z);
  EXPECT_EQ(f.calls, 3);
  EXPECT_DOUBLE_EQ(z[0], 0.16);
}

TEST(ConstrainedFactor, UnmeasuredValuesServeOnlyWhileNoMultiplierIsSet) {
  graph::Values v;
  v.insert(q_key(0), Eigen::VectorXd::Constant(1, 0.3));
  CountingFactor f(/*values_only=*/true, /*unmeasured=*/true);
  Eigen::VectorXd z, r;
  Eigen::MatrixXd J;
  f.values_at(v, z);
  f.values_at(v, z);
  EXPECT_EQ(f.calls, 1);
  auto m = std::make_shared<Multipliers>(1, 10.0);
  m->lower[0] = 1.0;
  f.bind(m);
  f.values_at(v, z);  // a multiplier needs every row measured
  EXPECT_EQ(f.calls, 2);
  EXPECT_THROW(f.linearize(v, r, J), std::logic_error);
}

TEST(DynamicsStepFactor, JacobiansOnIiwaWithPayloadAndAcrobot) {
  std::mt19937 rng(3);
  auto iiwa = std::make_shared<const dynamics::Model>(dynamics::attach_box_payload(
      *load("robots/iiwa14/iiwa14.urdf"), "iiwa_link_ee_kuka", 2.0, {0.1, 0.1, 0.1},
      Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.05))));
  for (auto model : {iiwa, testing::acrobot_model()}) {
    const int n = model->nq();
    graph::Values v = random_states(n, 0, rng);
    DynamicsStepOptions o;
    o.min_torque = 0.3;
    o.torque_scale = 2.0;
    auto ws = std::make_shared<DynamicsWorkspace>(model);
    DynamicsStepFactor f(0, model, ws, o);
    bind(f, 5);
    auto c = check_jacobians(f, v, {1e-6, 1e-5, false});
    EXPECT_TRUE(c.ok) << c.report();
    // Raw rows are the inverse-dynamics torques.
    Eigen::VectorXd z;
    f.values_at(v, z);
    dynamics::Data d(*model);
    const Eigen::VectorXd tau =
        dynamics::rnea(*model, d, v.at(q_key(0)), v.at(v_key(0)), v.at(a_key(0)));
    EXPECT_NEAR(z[z.size() - 1], tau[n - 1], 1e-12);
  }
}

TEST(DynamicsStepFactor, TorqueBoundsAloneLinearizeWhereverAHingeIsOn) {
  std::mt19937 rng(5);
  auto iiwa = std::make_shared<const dynamics::Model>(dynamics::attach_box_payload(
      *load("robots/iiwa14/iiwa14.urdf"), "iiwa_link_ee_kuka", 2.0, {0.1, 0.1, 0.1},
      Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.05))));
  const graph::Values v = random_states(7, 0, rng);
  auto ws = std::make_shared<DynamicsWorkspace>(iiwa);
  dynamics::Data d(*iiwa);
  const Eigen::VectorXd tau =
      dynamics::rnea(*iiwa, d, v.at(q_key(0)), v.at(v_key(0)), v.at(a_key(0)));
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  // Every torque within its bound and no multiplier: every hinge is off.
  DynamicsStepOptions loose;
  loose.limit_epsilon = 0;
  DynamicsStepFactor clear(0, iiwa, ws, loose);
  for (int j = 0; j < 7; ++j) ASSERT_LT(std::abs(tau[j]), iiwa->bodies[j].limits.effort);
  bind(clear, 100);
  clear.linearize(v, r, J);
  EXPECT_EQ(r.cwiseAbs().maxCoeff(), 0);
  EXPECT_EQ(J.cwiseAbs().maxCoeff(), 0);
  // A multiplier pushing on one row inside its bound turns that hinge on.
  Eigen::VectorXd upper = Eigen::VectorXd::Zero(7);
  upper[1] = 1e7;  // λ/√μ far beyond √μ times the row's scaled distance to its bound
  bind(clear, 100, Eigen::VectorXd::Zero(7), upper);
  clear.linearize(v, r, J);
  EXPECT_GT(J.row(1).cwiseAbs().maxCoeff(), 0);
  auto c = check_jacobians(clear, v, {1e-6, 1e-5, false});
  EXPECT_TRUE(c.ok) << c.report();
  // Bounds tight enough that torques pass them: those rows need their Jacobian rows.
  DynamicsStepOptions tight;
  tight.limit_epsilon = iiwa->bodies[0].limits.effort - 1;
  DynamicsStepFactor pressed(0, iiwa, ws, tight);
  bind(pressed, 100);
  pressed.linearize(v, r, J);
  EXPECT_GT(J.cwiseAbs().maxCoeff(), 0);
  c = check_jacobians(pressed, v, {1e-6, 1e-5, false});
  EXPECT_TRUE(c.ok) << c.report();
}

TEST(PoseFactor, Jacobians) {
  std::mt19937 rng(4);
  auto model = load("robots/iiwa14/iiwa14.urdf");
  auto ws = std::make_shared<DynamicsWorkspace>(model);
  graph::Values v = random_states(7, 0, rng);
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  target.translation() = Eigen::Vector3d(0.4, 0.1, 0.6);
  for (PoseParts parts : {PoseParts::kFull, PoseParts::kPosition, PoseParts::kOrientation}) {
    PoseFactor f(0, model, ws, "iiwa_link_ee_kuka", target, parts, 0.01);
    auto c = check_jacobians(f, v);
    EXPECT_TRUE(c.ok) << c.report();
  }
}

TEST(CollisionFactor, JacobiansAtAndBetweenSteps) {
  std::mt19937 rng(5);
  auto model = load("robots/rr/rr.urdf");
  collision::Obstacle ball;
  ball.id = 7;
  ball.shape = collision::Shape::sphere(0.2);
  ball.pose.translation() = Eigen::Vector3d(0.9, 0, 1.3);
  auto ctx = std::make_shared<CollisionContext>(model, std::vector<collision::Obstacle>{ball}, 2.0);
  graph::Values v;
  v.insert(q_key(0), Eigen::Vector2d(0.5, 0.4));
  v.insert(v_key(0), Eigen::Vector2d(0.3, -0.2));
  v.insert(q_key(1), Eigen::Vector2d(0.7, 0.5));
  v.insert(v_key(1), Eigen::Vector2d(0.1, 0.4));
  for (double s : {0.0, 0.4}) {
    CollisionFactor f(0, s, 0.5, 0.05, 0.01, ctx);
    Eigen::VectorXd z;
    f.values_at(v, z);
    EXPECT_LT(z.minCoeff(), 2.0);  // some pair reported
    // GJK/EPA distances carry ~1e-8 m of noise: a 1e-4 step keeps it out of the differences.
    auto c = check_jacobians(f, v, {1e-4, 1e-3, false});
    EXPECT_TRUE(c.ok) << c.report();
  }
}

}  // namespace
}  // namespace kinograph::planning

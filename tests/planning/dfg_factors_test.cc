// Tests of the DFG factors (twist, acceleration, wrench balance, torque).
//
// Convention: the factors follow Lynch & Park eqs. 8.45–8.49 (V_i = Ad_{T_{i,λ}} V_λ + A_i q̇_i,
// V̇_i = Ad V̇_λ + A_i q̈_i + [ad_{V_i}] A_i q̇_i, F_i = Σ_c Ad^T_{T_{c,i}} F_c + G V̇ − ad^T G V,
// τ_i = A_i^T F_i + b q̇_i), not the paper's printed form, which shifts the joint index
// (q̇_{j−1}) and writes −A q̇: with the body frame on joint i's axis (as the Model places it),
// joint i's own rate moves body i, and the sign is + for a screw axis pointing along the joint's
// positive direction. Lynch & Park's form is what dynamics::rnea computes, so the consistency
// tests below check the factors against RNEA directly.
#include "kinograph/planning/factors/dfg_factors.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <memory>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/dynamics/payload.h"
#include "kinograph/graph/testing/numerical_jacobian.h"

namespace kinograph::planning {
namespace {

using dynamics::Model;
using dynamics::Vector6;
using graph::Key;

std::string robot(const std::string& rel) {
  return std::string(KINOGRAPH_SOURCE_DIR) + "/robots/" + rel;
}

// A small branching tree written for these tests: body a carries two children (b revolute,
// c prismatic with damping), c carries d; tilted origins and off-diagonal inertias so that no
// term hides behind a zero.
const char* kTreeUrdf = R"(<?xml version="1.0"?>
<robot name="dfg_tree">
  <link name="base"/>
  <joint name="ja" type="revolute">
    <parent link="base"/><child link="a"/>
    <origin xyz="0.1 0.0 0.2" rpy="0.1 0.2 0.3"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="50" velocity="3"/><dynamics damping="0.4"/>
  </joint>
  <link name="a">
    <inertial><origin xyz="0.03 0.01 0.1" rpy="0.2 0 0.1"/><mass value="2.5"/>
      <inertia ixx="0.04" ixy="0.003" ixz="-0.002" iyy="0.05" iyz="0.001" izz="0.02"/></inertial>
  </link>
  <joint name="jb" type="revolute">
    <parent link="a"/><child link="b"/>
    <origin xyz="0 0.1 0.3" rpy="0.9 -0.2 0.4"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="40" velocity="3"/>
  </joint>
  <link name="b">
    <inertial><origin xyz="0.15 -0.02 0.04" rpy="0 0.3 0"/><mass value="1.2"/>
      <inertia ixx="0.01" ixy="0.001" ixz="0" iyy="0.02" iyz="-0.001" izz="0.015"/></inertial>
  </link>
  <joint name="jc" type="prismatic">
    <parent link="a"/><child link="c"/>
    <origin xyz="0.05 -0.15 0.2" rpy="0 0.6 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-0.5" upper="0.5" effort="100" velocity="1"/><dynamics damping="1.5"/>
  </joint>
  <link name="c">
    <inertial><origin xyz="0.05 0.02 -0.03" rpy="0 0 0.2"/><mass value="1.0"/>
      <inertia ixx="0.02" ixy="0" ixz="0.001" iyy="0.01" iyz="0" izz="0.012"/></inertial>
  </link>
  <joint name="jd" type="revolute">
    <parent link="c"/><child link="d"/>
    <origin xyz="0.2 0 0.05" rpy="-0.5 0.1 0.2"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="20" velocity="3"/><dynamics damping="0.05"/>
  </joint>
  <link name="d">
    <inertial><origin xyz="0 0.1 0.02" rpy="0.3 0 0"/><mass value="0.6"/>
      <inertia ixx="0.004" ixy="0.0002" ixz="0" iyy="0.003" iyz="0.0001" izz="0.002"/></inertial>
  </link>
</robot>)";

// Which variables hold the joint scalars: the planner's joint vectors, one scalar per joint, or
// one stacked state [q; q̇; q̈] per step (exercises merged keys).
enum class JointLayout { kVectors, kScalars, kState };

struct Fixture {
  Model model;
  JointLayout layout;
  int n() const { return model.nq(); }

  JointScalar q(int j) const { return scalar(0, 'q', j); }
  JointScalar qd(int j) const { return scalar(1, 'v', j); }
  JointScalar qdd(int j) const { return scalar(2, 'a', j); }

  JointScalar scalar(int which, char kind, int j) const {
    switch (layout) {
      case JointLayout::kVectors:
        return {Key(kind, 0, 0), n(), j};
      case JointLayout::kScalars:
        return {Key(kind, j, 0), 1, 0};
      case JointLayout::kState:
        return {Key('x', 0, 0), 3 * n(), which * n() + j};
    }
    return {};
  }

  // Joint values in whatever layout, plus V, A, F, T per body (all independent random values, so
  // Jacobians are checked away from the consistent manifold too).
  void insert_joint_values(graph::Values& v, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                           const Eigen::VectorXd& qdd) const {
    switch (layout) {
      case JointLayout::kVectors:
        v.insert(Key('q', 0, 0), q);
        v.insert(Key('v', 0, 0), qd);
        v.insert(Key('a', 0, 0), qdd);
        break;
      case JointLayout::kScalars:
        for (int j = 0; j < n(); ++j) {
          v.insert(Key('q', j, 0), q.segment(j, 1));
          v.insert(Key('v', j, 0), qd.segment(j, 1));
          v.insert(Key('a', j, 0), qdd.segment(j, 1));
        }
        break;
      case JointLayout::kState: {
        Eigen::VectorXd x(3 * n());
        x << q, qd, qdd;
        v.insert(Key('x', 0, 0), x);
        break;
      }
    }
  }

  // All four factors of every body at step 0 with body variables V/A/F/T(i, 0).
  std::vector<std::shared_ptr<graph::Factor>> factors(
      const std::vector<Vector6>& external = {}) const {
    std::vector<std::shared_ptr<graph::Factor>> out;
    for (int i = 0; i < n(); ++i) {
      const int p = std::max(model.bodies[i].parent, 0);
      out.push_back(
          std::make_shared<DfgTwistFactor>(model, i, Key('V', i, 0), Key('V', p, 0), q(i), qd(i)));
      out.push_back(std::make_shared<DfgAccelFactor>(model, i, Key('A', i, 0), Key('A', p, 0),
                                                     Key('V', i, 0), q(i), qd(i), qdd(i)));
      std::vector<DfgChild> children;
      for (int c = n() - 1; c > i; --c) {  // reverse order: the factor must not rely on it
        if (model.bodies[c].parent == i) children.push_back({c, Key('F', c, 0), q(c)});
      }
      const Vector6 ext = external.empty() ? Vector6::Zero() : external[i];
      out.push_back(std::make_shared<DfgWrenchFactor>(model, i, Key('F', i, 0), Key('A', i, 0),
                                                      Key('V', i, 0), children, ext));
      out.push_back(std::make_shared<DfgTorqueFactor>(model, i, JointScalar{Key('T', i, 0), 1, 0},
                                                      Key('F', i, 0), qd(i)));
    }
    return out;
  }
};

Eigen::VectorXd uniform(std::mt19937& rng, int n, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

double max_raw_error(const graph::Factor& f, const graph::Values& values) {
  std::vector<const double*> ptrs;
  for (Key k : f.keys()) ptrs.push_back(values.at(k).data());
  Eigen::VectorXd e = Eigen::VectorXd::Zero(f.residual_dim());
  f.evaluate(graph::FactorValues(ptrs.data(), f.dims().data()), e, nullptr);
  return e.cwiseAbs().maxCoeff();
}

struct RobotCase {
  std::string name;
  std::string urdf;  // path under robots/, or empty for the tree
  bool payload = false;
};

void PrintTo(const RobotCase& rc, std::ostream* os) { *os << rc.name; }

Model load(const RobotCase& rc) {
  Model m =
      rc.urdf.empty() ? Model::from_urdf_string(kTreeUrdf) : Model::from_urdf_file(robot(rc.urdf));
  if (rc.payload) {
    m = dynamics::attach_box_payload(m, "iiwa_link_ee_kuka", 2.0, {0.1, 0.1, 0.1},
                                     Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.05)));
  }
  return m;
}

class DfgFactorsTest : public ::testing::TestWithParam<RobotCase> {};

// Every block of every factor against central differences, at random (inconsistent) values,
// for all three ways of storing the joint scalars.
TEST_P(DfgFactorsTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(1234);
  for (JointLayout layout : {JointLayout::kVectors, JointLayout::kScalars, JointLayout::kState}) {
    Fixture fx{load(GetParam()), layout};
    const int n = fx.n();
    for (int trial = 0; trial < 3; ++trial) {
      graph::Values values;
      fx.insert_joint_values(values, uniform(rng, n, 2.5), uniform(rng, n, 2.0),
                             uniform(rng, n, 4.0));
      std::vector<Vector6> ext(n);
      for (int i = 0; i < n; ++i) {
        values.insert(Key('V', i, 0), uniform(rng, 6, 2.0));
        values.insert(Key('A', i, 0), uniform(rng, 6, 5.0));
        values.insert(Key('F', i, 0), uniform(rng, 6, 20.0));
        values.insert(Key('T', i, 0), uniform(rng, 1, 10.0));
        ext[i] = uniform(rng, 6, 3.0);
      }
      for (const auto& f : fx.factors(ext)) {
        const auto check = graph::testing::check_jacobians(*f, values);
        EXPECT_TRUE(check.ok) << GetParam().name << " layout " << static_cast<int>(layout) << " "
                              << f->name() << " " << f->keys()[0].to_string() << "\n"
                              << check.report();
      }
    }
  }
}

// RNEA's body twists, accelerations, wrenches and torques satisfy every factor, and the torque
// factor reproduces rnea's τ (damping and, for the iiwa case, the payload included).
TEST_P(DfgFactorsTest, RneaValuesSatisfyEveryFactor) {
  std::mt19937 rng(99);
  Fixture fx{load(GetParam()), JointLayout::kVectors};
  const int n = fx.n();
  dynamics::Data data(fx.model);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd q = uniform(rng, n, 3.0), qd = uniform(rng, n, 2.0),
                          qdd = uniform(rng, n, 5.0);
    // An external wrench on the last body (a push by the environment), in its frame.
    std::vector<dynamics::ExternalWrench> ext{{n - 1, uniform(rng, 6, 5.0)}};
    dynamics::rnea(fx.model, data, q, qd, qdd, ext);
    graph::Values values;
    fx.insert_joint_values(values, q, qd, qdd);
    double scale = 1.0;
    for (int i = 0; i < n; ++i) {
      values.insert(Key('V', i, 0), data.V[i]);
      values.insert(Key('A', i, 0), data.Vdot[i]);
      values.insert(Key('F', i, 0), data.F[i]);
      values.insert(Key('T', i, 0), data.tau.segment(i, 1));
      scale =
          std::max({scale, data.F[i].cwiseAbs().maxCoeff(), data.Vdot[i].cwiseAbs().maxCoeff()});
    }
    std::vector<Vector6> ext_per_body(n, Vector6::Zero());
    ext_per_body[n - 1] = ext[0].wrench;
    for (const auto& f : fx.factors(ext_per_body)) {
      EXPECT_LT(max_raw_error(*f, values), 1e-12 * scale)
          << GetParam().name << " " << f->name() << " " << f->keys()[0].to_string();
    }
  }
}

// Torques from the DFG equations alone (a forward pass of the twist and acceleration factors,
// a backward pass of the wrench factors, then the torque factors) equal rnea's; independent of
// how rnea stores its intermediate values.
TEST_P(DfgFactorsTest, TorqueFactorMatchesRneaTorque) {
  std::mt19937 rng(7);
  Fixture fx{load(GetParam()), JointLayout::kVectors};
  const int n = fx.n();
  dynamics::Data data(fx.model);
  const Eigen::VectorXd q = uniform(rng, n, 3.0), qd = uniform(rng, n, 2.0),
                        qdd = uniform(rng, n, 5.0);
  const Eigen::VectorXd tau = dynamics::rnea(fx.model, data, q, qd, qdd);

  // Solve each factor for its first variable: with that variable at zero, e = −RHS.
  graph::Values values;
  fx.insert_joint_values(values, q, qd, qdd);
  for (int i = 0; i < n; ++i) {
    for (char k : {'V', 'A', 'F'}) values.insert(Key(k, i, 0), Vector6::Zero());
    values.insert(Key('T', i, 0), Eigen::VectorXd::Zero(1));
  }
  const auto factors = fx.factors();
  auto solve_first = [&](const graph::Factor& f) {
    std::vector<const double*> ptrs;
    for (Key k : f.keys()) ptrs.push_back(values.at(k).data());
    Eigen::VectorXd e = Eigen::VectorXd::Zero(f.residual_dim());
    f.evaluate(graph::FactorValues(ptrs.data(), f.dims().data()), e, nullptr);
    values.at(f.keys()[0]) -= e;  // e is affine with unit slope in the first variable
  };
  for (int i = 0; i < n; ++i) {  // forward: twists, then accelerations
    solve_first(*factors[4 * i]);
    solve_first(*factors[4 * i + 1]);
  }
  for (int i = n - 1; i >= 0; --i) solve_first(*factors[4 * i + 2]);  // backward: wrenches
  for (int i = 0; i < n; ++i) {
    solve_first(*factors[4 * i + 3]);
    EXPECT_NEAR(values.at(Key('T', i, 0))[0], tau[i], 1e-9 * std::max(1.0, std::abs(tau[i])))
        << GetParam().name << " joint " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(Robots, DfgFactorsTest,
                         ::testing::Values(RobotCase{"acrobot", "acrobot/acrobot.urdf"},
                                           RobotCase{"rr", "rr/rr.urdf"},
                                           RobotCase{"iiwa14", "iiwa14/iiwa14.urdf"},
                                           RobotCase{"iiwa14_payload", "iiwa14/iiwa14.urdf", true},
                                           RobotCase{"tree", ""}),
                         [](const auto& info) { return info.param.name; });

// The Acrobot in closed form (Spong's equations, Drake's parameters, damping 0.1): the DFG's
// torques at a state equal M q̈ + C q̇ + G + b q̇ computed by hand.
TEST(DfgFactors, AcrobotClosedForm) {
  Fixture fx{Model::from_urdf_file(robot("acrobot/acrobot.urdf")), JointLayout::kScalars};
  const double m1 = 1, m2 = 1, l1 = 1, lc1 = 0.5, lc2 = 1, g = 9.81, b = 0.1;
  // Inertias about the joints (Spong's I1, I2): COM inertias plus m·lc².
  const double I1 = 0.083 + m1 * lc1 * lc1, I2 = 0.33 + m2 * lc2 * lc2;
  const Eigen::Vector2d q(0.7, -1.1), qd(0.4, 1.3), qdd(-0.8, 2.1);
  const double c2 = std::cos(q[1]), s1 = std::sin(q[0]), s2 = std::sin(q[1]),
               s12 = std::sin(q[0] + q[1]);
  Eigen::Matrix2d M;
  M << I1 + I2 + m2 * l1 * l1 + 2 * m2 * l1 * lc2 * c2, I2 + m2 * l1 * lc2 * c2,
      I2 + m2 * l1 * lc2 * c2, I2;
  Eigen::Matrix2d C;
  C << -2 * m2 * l1 * lc2 * s2 * qd[1], -m2 * l1 * lc2 * s2 * qd[1], m2 * l1 * lc2 * s2 * qd[0], 0;
  const Eigen::Vector2d G(g * (m1 * lc1 + m2 * l1) * s1 + m2 * g * lc2 * s12, m2 * g * lc2 * s12);
  const Eigen::Vector2d expected = M * qdd + C * qd + G + b * qd;

  dynamics::Data data(fx.model);
  dynamics::rnea(fx.model, data, q, qd, qdd);
  graph::Values values;
  fx.insert_joint_values(values, q, qd, qdd);
  for (int i = 0; i < 2; ++i) {
    values.insert(Key('V', i, 0), data.V[i]);
    values.insert(Key('A', i, 0), data.Vdot[i]);
    values.insert(Key('F', i, 0), data.F[i]);
    values.insert(Key('T', i, 0), expected.segment(i, 1));  // the hand-computed torque
  }
  for (const auto& f : fx.factors()) {
    EXPECT_LT(max_raw_error(*f, values), 1e-9) << f->name() << " " << f->keys()[0].to_string();
  }
}

TEST(DfgFactors, RejectsBadInput) {
  const Model m = Model::from_urdf_string(kTreeUrdf);
  const JointScalar q{Key('q', 0, 0), m.nq(), 0}, qd{Key('v', 0, 0), m.nq(), 0};
  EXPECT_THROW(DfgTwistFactor(m, m.nq(), Key('V', 0, 0), Key('V', 0, 0), q, qd),
               std::invalid_argument);
  EXPECT_THROW(DfgTwistFactor(m, 0, Key('V', 0, 0), Key('V', 0, 0), {Key('q', 0, 0), 2, 2}, qd),
               std::invalid_argument);
  // The same key with two dimensions.
  EXPECT_THROW(DfgTwistFactor(m, 0, Key('V', 0, 0), Key('V', 0, 0), q, {Key('q', 0, 0), 1, 0}),
               std::invalid_argument);
  // Body a (0) has children b (1) and c (2); listing only b is an error.
  EXPECT_THROW(DfgWrenchFactor(m, 0, Key('F', 0, 0), Key('A', 0, 0), Key('V', 0, 0),
                               {{1, Key('F', 1, 0), {Key('q', 0, 0), m.nq(), 1}}}),
               std::invalid_argument);
  // Without damping the torque factor has no q̇ key; with damping it has.
  EXPECT_EQ(DfgTorqueFactor(m, 1, {Key('T', 1, 0), 1, 0}, Key('F', 1, 0), qd).keys().size(), 2u);
  EXPECT_EQ(DfgTorqueFactor(m, 2, {Key('T', 2, 0), 1, 0}, Key('F', 2, 0), qd).keys().size(), 3u);
}

}  // namespace
}  // namespace kinograph::planning

// The Jacobian checker accepts correct factors and catches a deliberately wrong Jacobian.
#include "kinograph/graph/testing/numerical_jacobian.h"

#include <gtest/gtest.h>

#include "tests/graph/problems.h"

namespace kinograph::graph {
namespace {

// sin/cos factor with a switch that corrupts one Jacobian entry.
class TrigFactor final : public Factor {
 public:
  TrigFactor(Key a, Key b, bool wrong) : Factor({a, b}, {2, 1}, 2), wrong_(wrong) {}
  void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                const Jacobians* J) const override {
    const auto p = x[0];
    const double t = x[1][0];
    e[0] = std::sin(p[0]) * t;
    e[1] = std::cos(p[1]) + p[0] * p[1];
    if (J) {
      auto A = J->block(0);
      A(0, 0) = std::cos(p[0]) * t;
      A(1, 0) = p[1];
      A(1, 1) = -std::sin(p[1]) + p[0];
      J->block(1)(0, 0) = std::sin(p[0]) * (wrong_ ? 1.01 : 1.0);
    }
  }

 private:
  bool wrong_;
};

Values trig_values() {
  Values v;
  v.insert(Key('p', 0, 0), Eigen::Vector2d(0.3, -0.7));
  v.insert(Key('t', 0, 0), Eigen::VectorXd::Constant(1, 1.7));
  return v;
}

TEST(NumericalJacobian, AcceptsCorrectFactors) {
  const auto check =
      testing::check_jacobians(TrigFactor(Key('p', 0, 0), Key('t', 0, 0), false), trig_values());
  EXPECT_TRUE(check.ok) << check.report();
  EXPECT_LT(check.max_rel_error, 1e-8);
  ASSERT_EQ(check.blocks.size(), 2u);

  auto chain = problems::chain(4);
  for (size_t i = 0; i < chain.graph.size(); ++i) {
    for (bool whitened : {false, true}) {
      testing::JacobianCheckOptions o;
      o.whitened = whitened;
      const auto c = testing::check_jacobians(*chain.graph[i], chain.start, o);
      EXPECT_TRUE(c.ok) << "factor " << i << ": " << c.report();
    }
  }
}

TEST(NumericalJacobian, CatchesAWrongBlockAndNamesIt) {
  const auto check =
      testing::check_jacobians(TrigFactor(Key('p', 0, 0), Key('t', 0, 0), true), trig_values());
  EXPECT_FALSE(check.ok);
  EXPECT_TRUE(check.blocks[0].ok);
  EXPECT_FALSE(check.blocks[1].ok);
  EXPECT_NEAR(check.blocks[1].max_abs_error, 0.01 * std::sin(0.3), 1e-8);
  EXPECT_NE(check.report().find("t(0,0)"), std::string::npos);
}

}  // namespace
}  // namespace kinograph::graph

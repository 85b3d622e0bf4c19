// A collision factor close to its last query (every distance provably still beyond its ε, no
// multiplier positive) answers from that query instead of asking the world again: its residual
// and Jacobian must be exactly a fresh factor's, and it must ask again when a multiplier is
// positive or an obstacle moved. On the iiwa with the desk, a leg, the floor and its self pairs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "kinograph/planning/clearance_world.h"
#include "kinograph/planning/factors/collision_factors.h"
#include "kinograph/planning/factors/trajectory_factors.h"
#include "measured_values.h"
#include "test_problems.h"

namespace kinograph::planning {
namespace {

using testing::box_obstacle;

struct Evaluation {
  Eigen::VectorXd z, r;
  Eigen::MatrixXd J;
};

// The raw distances (every reported pair measured), and the whitened residual and Jacobian,
// of `f` at q.
Evaluation evaluate(const CollisionFactor& f, const Eigen::VectorXd& q) {
  const double* ptrs[1] = {q.data()};
  const graph::FactorValues x(ptrs, f.dims().data());
  Evaluation e{testing::measured_values(f, x), Eigen::VectorXd::Zero(f.residual_dim()),
               Eigen::MatrixXd::Zero(f.residual_dim(), f.jacobian_cols())};
  Eigen::Ref<Eigen::MatrixXd> J(e.J);
  f.whitened(ptrs, e.r, &J);
  return e;
}

class CollisionLastQuery : public ::testing::Test {
 protected:
  CollisionLastQuery() : model(testing::iiwa_with_block()) {
    const std::vector<collision::Obstacle> obstacles = {
        box_obstacle(0, {0.5, 1.0, 0.04}, {0.75, 0, 0.64}),
        box_obstacle(1, {0.04, 0.04, 0.62}, {0.52, 0.48, 0.31}), floor_obstacle(0.0)};
    SelfPairs self{{{4, 6}}, 0.01};
    context = std::make_shared<CollisionContext>(model, obstacles, 0.08, &self, true);
  }

  Eigen::VectorXd random_q() {
    Eigen::VectorXd q(model->nq());
    for (int j = 0; j < model->nq(); ++j) {
      const auto& lim = model->bodies[j].limits;
      q[j] = std::uniform_real_distribution<double>(lim.lower, lim.upper)(rng);
    }
    return q;
  }

  std::shared_ptr<const dynamics::Model> model;
  std::shared_ptr<CollisionContext> context;
  std::mt19937 rng{11};
};

TEST_F(CollisionLastQuery, NearTheLastQueryTheRowsAreAFreshFactors) {
  int answered_from_last = 0, asked_again = 0, moved_into_contact = 0;
  for (int trial = 0; trial < 250; ++trial) {
    const Eigen::VectorXd q0 = random_q();
    // Steps from far below to far above what the gap allows, and every fifth a configuration
    // anywhere (often with pairs inside their ε that were clear at q0).
    const double step = 1e-4 * std::pow(10.0, trial % 5);
    Eigen::VectorXd q1 = q0;
    for (int j = 0; j < q1.size(); ++j) {
      q1[j] += std::uniform_real_distribution<double>(-step, step)(rng);
    }
    if (trial % 5 == 4) q1 = random_q();
    const CollisionFactor kept(0, 0.0, 0.1, 0.05, 0.01, context);
    evaluate(kept, q0);
    const Evaluation a = evaluate(kept, q1);
    const Evaluation b = evaluate(CollisionFactor(0, 0.0, 0.1, 0.05, 0.01, context), q1);
    EXPECT_EQ(a.r, b.r) << "trial " << trial;
    EXPECT_EQ(a.J, b.J) << "trial " << trial;
    (a.z == b.z ? asked_again : answered_from_last) += 1;
    moved_into_contact += !b.r.isZero() ? 1 : 0;
  }
  EXPECT_GT(answered_from_last, 40);
  EXPECT_GT(asked_again, 40);
  EXPECT_GT(moved_into_contact, 20);
}

TEST_F(CollisionLastQuery, APositiveMultiplierOrAMovedObstacleAsksAgain) {
  int answered_from_last = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::VectorXd q = random_q();
    CollisionFactor f(0, 0.0, 0.1, 0.05, 0.01, context);
    const Eigen::VectorXd z0 = evaluate(f, q).z;
    const Eigen::VectorXd q1 = q + Eigen::VectorXd::Constant(q.size(), 1e-9);
    const Evaluation fresh = evaluate(CollisionFactor(0, 0.0, 0.1, 0.05, 0.01, context), q1);
    answered_from_last += evaluate(f, q1).z == z0 && fresh.z != z0 ? 1 : 0;
    // A multiplier on a row makes every row count again.
    auto m = std::make_shared<Multipliers>(f.residual_dim(), 10.0);
    m->lower[trial % f.residual_dim()] = 1.0;
    f.bind(m);
    EXPECT_EQ(evaluate(f, q1).z, fresh.z) << "trial " << trial;
  }
  EXPECT_GT(answered_from_last, 20);  // the shortcut was there to refuse
  // The desk moves: the last query saw it elsewhere.
  CollisionFactor f(0, 0.0, 0.1, 0.05, 0.01, context);
  Eigen::VectorXd q = random_q();
  evaluate(f, q);
  Eigen::Isometry3d pose = context->obstacles[0].pose;
  pose.translation().z() += 0.3;
  ASSERT_TRUE(context->move_obstacle(0, pose).ok);
  const Evaluation moved = evaluate(f, q);
  EXPECT_EQ(moved.z, evaluate(CollisionFactor(0, 0.0, 0.1, 0.05, 0.01, context), q).z);
}

// Values alone without multipliers (a cost, a violation) measure only the pairs within their ε:
// the whitened rows are those of an evaluation that measures every pair, the rows within their
// ε read their distances and the others some value beyond it. Once a multiplier is set, values
// read again at the same point are measured in full: the kept evaluation no longer stands in.
TEST_F(CollisionLastQuery, ValuesAloneMeasureOnlyThePairsWithinTheirEpsilon) {
  int unmeasured = 0, inside = 0;
  Eigen::VectorXd q_unmeasured;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::VectorXd q = random_q();
    const double* ptrs[1] = {q.data()};
    const CollisionFactor alone(0, 0.0, 0.1, 0.05, 0.01, context);
    const graph::FactorValues x(ptrs, alone.dims().data());
    Eigen::VectorXd z = Eigen::VectorXd::Zero(alone.residual_dim());
    alone.compute(x, z, nullptr);
    const CollisionFactor measuring(0, 0.0, 0.1, 0.05, 0.01, context);
    const Eigen::VectorXd full = testing::measured_values(measuring, x);
    Eigen::VectorXd r_alone = Eigen::VectorXd::Zero(alone.residual_dim());
    CollisionFactor(0, 0.0, 0.1, 0.05, 0.01, context).whitened(ptrs, r_alone, nullptr);
    EXPECT_EQ(r_alone, evaluate(CollisionFactor(0, 0.0, 0.1, 0.05, 0.01, context), q).r)
        << "trial " << trial;
    for (int i = 0; i < z.size(); ++i) {
      const double lower = alone.rows()[static_cast<size_t>(i)].lower;
      if (full[i] <= lower) {
        EXPECT_EQ(z[i], full[i]) << "trial " << trial << " row " << i;
        ++inside;
      } else {
        EXPECT_GT(z[i], lower) << "trial " << trial << " row " << i;
        if (z[i] != full[i]) {
          ++unmeasured;
          q_unmeasured = q;
        }
      }
    }
  }
  EXPECT_GT(inside, 20);
  ASSERT_GT(unmeasured, 20);
  graph::Values v;
  v.insert(q_key(0), q_unmeasured);
  CollisionFactor f(0, 0.0, 0.1, 0.05, 0.01, context);
  Eigen::VectorXd alone, bound;
  f.values_at(v, alone);
  const Eigen::VectorXd full = testing::measured_values(f, v);
  EXPECT_NE(alone, full);
  auto m = std::make_shared<Multipliers>(f.residual_dim(), 10.0);
  m->lower[0] = 1.0;
  f.bind(m);
  f.values_at(v, bound);
  EXPECT_EQ(bound, full);
}

// The whitened rows are the hinges of the raw distances (unbound: μ = 1, λ = 0): zero and with
// a zero Jacobian row for every pair beyond its ε, (ε − z)/s for one inside. A factor that has
// proven every row clear skips evaluate()'s per-row test; this holds it to what that test gives,
// at fresh queries and at answers from the last one.
TEST_F(CollisionLastQuery, TheWhitenedRowsAreTheHingesOfTheRawDistances) {
  int clear = 0, inside = 0;
  CollisionFactor kept(0, 0.0, 0.1, 0.05, 0.01, context);
  Eigen::VectorXd q = random_q();
  for (int trial = 0; trial < 300; ++trial) {
    q = trial % 3 == 0 ? random_q() : Eigen::VectorXd(q.array() + 1e-5);
    for (const bool from_kept : {true, false}) {
      const CollisionFactor fresh(0, 0.0, 0.1, 0.05, 0.01, context);
      const Evaluation e = evaluate(from_kept ? kept : fresh, q);
      bool any_inside = false;
      for (int i = 0; i < e.z.size(); ++i) {
        const RowSpec& row = kept.rows()[static_cast<size_t>(i)];
        const double hinge = std::max(0.0, (row.lower - e.z[i]) / row.scale);
        ASSERT_EQ(e.r[i], hinge) << "trial " << trial << " row " << i;
        if (hinge == 0) {
          EXPECT_TRUE(e.J.row(i).isZero()) << "trial " << trial << " row " << i;
        } else {
          any_inside = true;
        }
      }
      (any_inside ? inside : clear) += 1;
    }
  }
  EXPECT_GT(clear, 100);
  EXPECT_GT(inside, 100);
}

}  // namespace
}  // namespace kinograph::planning

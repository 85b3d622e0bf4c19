// Culling in the collision hinge changes nothing: on the iiwa with the desk, the floor and its
// self pairs, a factor whose world culls by link and geometry bounds gives exactly (bit for bit)
// the values and Jacobians of one whose world runs GJK on every pair, at random configurations
// and at configurations placed by bisection exactly at the query distance, the hinge's ε and
// contact.
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "kinograph/planning/clearance_world.h"
#include "kinograph/planning/factors/collision_factors.h"
#include "kinograph/planning/factors/trajectory_factors.h"
#include "test_problems.h"

namespace kinograph::planning {
namespace {

using testing::box_obstacle;

struct Evaluation {
  Eigen::VectorXd z;
  Eigen::MatrixXd J;
};

// The factor's raw signed distances and their Jacobian (not whitened by the hinge).
Evaluation evaluate(const CollisionFactor& f, const graph::Values& v) {
  std::vector<const double*> ptrs;
  for (const graph::Key& k : f.keys()) ptrs.push_back(v.at(k).data());
  Evaluation e{Eigen::VectorXd::Zero(f.residual_dim()),
               Eigen::MatrixXd::Zero(f.residual_dim(), f.jacobian_cols())};
  const graph::FactorValues x(ptrs.data(), f.dims().data());
  const graph::Jacobians J(e.J.data(), e.J.rows(), e.J.rows(), f.block_offsets().data(),
                           f.dims().data());
  f.compute(x, e.z, &J);
  return e;
}

class CollisionCull : public ::testing::Test {
 protected:
  CollisionCull() : model(testing::iiwa_with_block()) {
    // The desk of robots/scenes/iiwa_desk.yaml and the floor; the wrist pair allowed.
    obstacles = {box_obstacle(0, {0.5, 1.0, 0.04}, {0.75, 0, 0.64}),
                 box_obstacle(1, {0.04, 0.04, 0.62}, {0.52, 0.48, 0.31}),
                 box_obstacle(2, {0.04, 0.04, 0.62}, {0.98, -0.48, 0.31})};
    SelfPairs self{{{4, 6}}, 0.01};
    std::vector<collision::Obstacle> floor = {floor_obstacle(0.0)};
    // The planner's query distances: ε + 0.03 m.
    desk = std::make_shared<CollisionContext>(model, obstacles, 0.08, nullptr, true);
    desk_ref = std::make_shared<CollisionContext>(model, obstacles, 0.08, nullptr, false);
    own = std::make_shared<CollisionContext>(model, floor, 0.04, &self, true);
    own_ref = std::make_shared<CollisionContext>(model, floor, 0.04, &self, false);
  }

  Eigen::VectorXd random_q(std::mt19937& rng) const {
    Eigen::VectorXd q(model->nq());
    for (int j = 0; j < model->nq(); ++j) {
      const auto& lim = model->bodies[j].limits;
      q[j] = std::uniform_real_distribution<double>(lim.lower, lim.upper)(rng);
    }
    return q;
  }

  // Both contexts' factors at (k = 0, s) agree exactly at the states in v; returns the smallest
  // distance of the reference (for the bisection) and counts the rows reported.
  double expect_same(const graph::Values& v, double s, const std::string& what) {
    double smallest = INFINITY;
    for (const auto& [fast, ref] : {std::pair{desk, desk_ref}, std::pair{own, own_ref}}) {
      const CollisionFactor a(0, s, 0.1, 0.01, 0.01, fast), b(0, s, 0.1, 0.01, 0.01, ref);
      const Evaluation ea = evaluate(a, v), eb = evaluate(b, v);
      EXPECT_EQ(ea.z, eb.z) << what;
      EXPECT_EQ(ea.J, eb.J) << what;
      for (int i = 0; i < eb.z.size(); ++i) reported += eb.z[i] < ref->query_distance;
      if (ref == own_ref) smallest = eb.z.minCoeff();
    }
    return smallest;
  }

  std::shared_ptr<const dynamics::Model> model;
  std::vector<collision::Obstacle> obstacles;
  std::shared_ptr<CollisionContext> desk, desk_ref, own, own_ref;
  int reported = 0;
};

TEST_F(CollisionCull, RandomConfigurationsAndHermiteStatesMatchTheReference) {
  std::mt19937 rng(21);
  for (int trial = 0; trial < 150; ++trial) {
    graph::Values v;
    v.insert(q_key(0), random_q(rng));
    v.insert(v_key(0), 0.5 * random_q(rng));
    v.insert(q_key(1), random_q(rng));
    v.insert(v_key(1), 0.5 * random_q(rng));
    for (double s : {0.0, 0.5}) expect_same(v, s, "trial " + std::to_string(trial));
  }
  EXPECT_GT(reported, 300);
}

// Along the straight line from a configuration clear of its own links and the floor to one that
// is not, bisection finds where the smallest self or floor distance is exactly the query distance,
// the self ε and zero; every step of it is compared.
TEST_F(CollisionCull, NearContactConfigurationsMatchTheReference) {
  std::mt19937 rng(22);
  int placed = 0;
  for (int trial = 0; trial < 150 && placed < 45; ++trial) {
    const Eigen::VectorXd q0 = random_q(rng), q1 = random_q(rng);
    graph::Values v;
    v.insert(q_key(0), q0);
    const auto min_at = [&](double u) {
      v.update(q_key(0), q0 + u * (q1 - q0));
      return expect_same(v, 0.0, "trial " + std::to_string(trial) + " u " + std::to_string(u));
    };
    const double d0 = min_at(0), d1 = min_at(1);
    for (const double target : {0.04 - 1e-9, 0.01, 0.0}) {
      if (!(d0 > target && d1 < target)) continue;
      double lo = 0, hi = 1;
      for (int i = 0; i < 40; ++i) {
        const double mid = 0.5 * (lo + hi);
        (min_at(mid) > target ? lo : hi) = mid;
      }
      EXPECT_NEAR(min_at(lo), target, 1e-6);
      ++placed;
    }
  }
  EXPECT_GE(placed, 30);
}

}  // namespace
}  // namespace kinograph::planning

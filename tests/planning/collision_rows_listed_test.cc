// A collision factor given a row list gets its Jacobian unzeroed (most of its rows are clear
// pairs): the rows it lists must be exactly those, and hold exactly the values, of an evaluation
// into a zeroed Jacobian, including rows a multiplier keeps on although their pair is too far
// for a gradient. Checked on the iiwa with the desk, the floor and its self pairs, at knots and
// between them, with J filled with NaN beforehand.
#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "kinograph/planning/clearance_world.h"
#include "kinograph/planning/factors/collision_factors.h"
#include "kinograph/planning/factors/trajectory_factors.h"
#include "listed_rows.h"
#include "test_problems.h"

namespace kinograph::planning {
namespace {

using testing::box_obstacle;
using testing::Linearization;
using testing::linearize;


TEST(CollisionRowsListed, ListedRowsEqualAZeroedEvaluation) {
  const auto model = testing::iiwa_with_block();
  const std::vector<collision::Obstacle> obstacles = {
      box_obstacle(0, {0.5, 1.0, 0.04}, {0.75, 0, 0.64}),
      box_obstacle(1, {0.04, 0.04, 0.62}, {0.52, 0.48, 0.31}), floor_obstacle(0.0)};
  SelfPairs self{{{4, 6}}, 0.01};
  const auto context = std::make_shared<CollisionContext>(model, obstacles, 0.08, &self, true);
  std::mt19937 rng(7);
  const auto random_q = [&] {
    Eigen::VectorXd q(model->nq());
    for (int j = 0; j < model->nq(); ++j) {
      const auto& lim = model->bodies[j].limits;
      q[j] = std::uniform_real_distribution<double>(lim.lower, lim.upper)(rng);
    }
    return q;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  int listed = 0, kept_on_far = 0;
  for (int trial = 0; trial < 60; ++trial) {
    graph::Values v;
    v.insert(q_key(0), random_q());
    v.insert(v_key(0), 0.5 * random_q());
    v.insert(q_key(1), random_q());
    v.insert(v_key(1), 0.5 * random_q());
    for (double s : {0.0, 0.5}) {
      CollisionFactor f(0, s, 0.1, 0.05, 0.01, context);
      EXPECT_TRUE(f.writes_listed_rows_only());
      // Every third row's multiplier is large enough to keep its hinge on however far its pair.
      auto m = std::make_shared<Multipliers>(f.residual_dim(), 10.0);
      for (int i = 0; i < f.residual_dim(); i += 3) m->lower[i] = 50.0;
      f.bind(m);
      const Linearization whole = linearize(f, v, 0.0, false);
      const Linearization part = linearize(f, v, nan, true);
      EXPECT_EQ(part.r, whole.r);
      const std::vector<int>& rows = part.support.all ? std::vector<int>() : part.support.rows;
      for (int i = 0; i < f.residual_dim(); ++i) {
        const bool in_list =
            part.support.all || std::binary_search(rows.begin(), rows.end(), i);
        if (!in_list) {
          EXPECT_TRUE(whole.J.row(i).isZero()) << "row " << i << " left out but not zero";
          continue;
        }
        ++listed;
        EXPECT_EQ(part.J.row(i), whole.J.row(i)) << "trial " << trial << " s " << s << " row " << i;
        kept_on_far += whole.J.row(i).isZero() ? 1 : 0;
      }
    }
  }
  EXPECT_GT(listed, 1000);
  EXPECT_GT(kept_on_far, 100);  // rows listed without a gradient were zeroed, not left as NaN
}

}  // namespace
}  // namespace kinograph::planning

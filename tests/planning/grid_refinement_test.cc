// Grid refinement: which coarse grid a fine problem is planned from, and the fine initialization
// read from the coarse plan's interpolant.
#include "kinograph/planning/batch/grid_refinement.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "kinograph/planning/formulation/planning_graph.h"
#include "kinograph/planning/trajectory_sampler.h"
#include "tests/planning/test_problems.h"

namespace kinograph::planning {
namespace {

Problem acrobot_at(int steps) {
  Problem p = testing::acrobot_swingup();  // 10 s
  p.steps = steps;
  return p;
}

TEST(GridRefinement, CoarseGridHalvesTheStepsDownToTheLongestInterval) {
  EXPECT_EQ(coarser_grid(acrobot_at(400), 0.1), 200);
  EXPECT_EQ(coarser_grid(acrobot_at(200), 0.1), 100);  // 0.1 s exactly: kept
  EXPECT_EQ(coarser_grid(acrobot_at(100), 0.1), 0);    // 0.2 s intervals would be too long
  EXPECT_EQ(coarser_grid(acrobot_at(300), 0.1), 150);  // the smallest factor: the nearest grid
  EXPECT_EQ(coarser_grid(acrobot_at(300), 0.05), 0);
  EXPECT_EQ(coarser_grid(acrobot_at(401), 0.1), 0);  // prime: nothing divides it
  EXPECT_EQ(coarser_grid(acrobot_at(400), 0), 0);    // off
  EXPECT_EQ(coarser_grid(acrobot_at(400), -1), 0);
  Problem iiwa = testing::iiwa_swing(30);  // 2 s: 15 steps are 0.133 s apart
  EXPECT_EQ(coarser_grid(iiwa, 0.1), 0);
  iiwa.steps = 40;
  EXPECT_EQ(coarser_grid(iiwa, 0.1), 20);
}

// The fine knots lie on the coarse interpolant: every second knot is a coarse one, the others
// the interpolant between; the actuated elbow's cubic (q̈ linear in time) is then the same curve
// on the fine grid, and the unpowered shoulder's integrated motion nearly so.
TEST(GridRefinement, FineStartLiesOnTheCoarseInterpolant) {
  const Problem coarse = acrobot_at(100), fine = acrobot_at(200);
  const Trajectory line = straight_line(coarse, coarse.goal.q);
  const Plan plan = plan_from_trajectory(coarse, line);
  const Trajectory tr = refined_start(fine, plan);
  ASSERT_EQ(tr.q.rows(), fine.steps + 1);
  TrajectorySampler on_coarse(*coarse.model, plan);
  for (int k = 0; k < fine.steps; ++k) {
    const InterpolantPoint p = on_coarse.at(k * fine.dt());
    EXPECT_NEAR((tr.q.row(k).transpose() - p.q).norm(), 0, 1e-12) << "knot " << k;
    EXPECT_NEAR((tr.qd.row(k).transpose() - p.qd).norm(), 0, 1e-12) << "knot " << k;
    EXPECT_NEAR((tr.qdd.row(k).transpose() - p.qdd).norm(), 0, 1e-12) << "knot " << k;
    if (k % 2 == 0) {
      EXPECT_NEAR((tr.q.row(k) - line.q.row(k / 2)).norm(), 0, 1e-12) << "knot " << k;
    }
  }
  EXPECT_NEAR((tr.q.row(fine.steps) - line.q.row(coarse.steps)).norm(), 0, 1e-12);  // the goal
  const Plan refined = plan_from_trajectory(fine, tr);
  TrajectorySampler on_fine(*fine.model, refined);
  double elbow = 0, shoulder = 0;
  for (double t = 0.013; t < coarse.horizon; t += 0.031) {
    const InterpolantPoint a = on_coarse.at(t), b = on_fine.at(t);
    elbow = std::max(elbow, std::abs(a.q[1] - b.q[1]));
    shoulder = std::max(shoulder, std::abs(a.q[0] - b.q[0]));
  }
  EXPECT_LT(elbow, 1e-12);
  EXPECT_LT(shoulder, 1e-6);
}

TEST(GridRefinement, RefusesAPlanWhoseGridDoesNotDivide) {
  const Problem coarse = acrobot_at(100);
  const Trajectory line = straight_line(coarse, coarse.goal.q);
  const Plan plan = plan_from_trajectory(coarse, line);
  EXPECT_THROW(refined_start(acrobot_at(150), plan), std::invalid_argument);
  EXPECT_NO_THROW(refined_start(acrobot_at(300), plan));
}

}  // namespace
}  // namespace kinograph::planning

// The joint-space path search that seeds the batch planner, and the trajectories through its
// waypoints: clearance checked by dense sampling of our own, determinism by seed, and each option
// against a run without it.
#include "kinograph/planning/batch/path_search.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "kinograph/collision/collision_world.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/clearance_world.h"
#include "kinograph/planning/formulation/initialization.h"
#include "kinograph/planning/io/scene.h"
#include "tests/planning/test_problems.h"

namespace kinograph::planning {
namespace {

const std::string kScenes = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/";

Problem desk() { return load_scene(kScenes + "iiwa_desk.yaml").problem; }

// Smallest obstacle distance and smallest floor/self distance along the path's segments, each
// sampled every 0.005 rad of its largest joint move (8× finer than the search checks).
struct PathClearance {
  double obstacles = std::numeric_limits<double>::infinity();
  double floor_and_self = std::numeric_limits<double>::infinity();
};
PathClearance dense_clearance(const Problem& p, const std::vector<Eigen::VectorXd>& path) {
  collision::CollisionWorldOptions brute;
  brute.cull = false;
  collision::CollisionWorld obstacles(*p.model, brute);
  for (const auto& o : p.obstacles) obstacles.add_obstacle(o);
  const std::unique_ptr<collision::CollisionWorld> rest = clearance_world(p, false);
  dynamics::Data data(*p.model);
  PathClearance c;
  for (size_t i = 0; i + 1 < path.size(); ++i) {
    const Eigen::VectorXd d = path[i + 1] - path[i];
    const int n = std::max(1, static_cast<int>(std::ceil(d.cwiseAbs().maxCoeff() / 0.005)));
    for (int s = 0; s <= n; ++s) {
      dynamics::forward_kinematics(*p.model, data, path[i] + d * (static_cast<double>(s) / n));
      c.obstacles = std::min(c.obstacles, obstacles.closest(data).distance);
      c.floor_and_self = std::min(c.floor_and_self, rest->closest(data).distance);
    }
  }
  return c;
}

double max_abs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }

TEST(PathSearch, DeskPathIsClearOfDeskFloorAndSelf) {
  const Problem p = desk();
  const std::optional<std::vector<Eigen::VectorXd>> path = search_path(p, p.goal.q);
  ASSERT_TRUE(path.has_value());
  ASSERT_GE(path->size(), 3u) << "the straight line hits the tabletop: the path must turn";
  EXPECT_EQ(max_abs(path->front() - p.start_q), 0.0);
  EXPECT_EQ(max_abs(path->back() - p.goal.q), 0.0);
  const PathClearance c = dense_clearance(p, *path);
  // Between the search's checks a link moves at most about 0.07 rad × 1.3 m: the 2 cm
  // obstacle clearance and the self ε keep the segments between them clear too.
  EXPECT_GT(c.obstacles, 0.0);
  EXPECT_GT(c.floor_and_self, 0.0);
}

TEST(PathSearch, StraightSegmentWhenItIsClear) {
  Problem p = testing::rr_reach();
  p.obstacles.clear();
  const auto path = search_path(p, p.goal.q);
  ASSERT_TRUE(path.has_value());
  EXPECT_EQ(path->size(), 2u);
}

TEST(PathSearch, MaxSamplesZeroNeverSearches) {
  const Problem p = desk();
  PathSearchOptions o;
  o.max_samples = 0;
  EXPECT_FALSE(search_path(p, p.goal.q, o).has_value());
  o.max_samples = 1;  // one sample cannot connect this start and goal
  EXPECT_FALSE(search_path(p, p.goal.q, o).has_value());
}

TEST(PathSearch, SeedChoosesThePath) {
  const Problem p = desk();
  PathSearchOptions o;
  const auto a = search_path(p, p.goal.q, o), b = search_path(p, p.goal.q, o);
  o.seed = 5;
  const auto c = search_path(p, p.goal.q, o);
  ASSERT_TRUE(a && b && c);
  ASSERT_EQ(a->size(), b->size());
  for (size_t i = 0; i < a->size(); ++i) EXPECT_EQ(max_abs((*a)[i] - (*b)[i]), 0.0);
  bool differs = a->size() != c->size();
  for (size_t i = 0; !differs && i < a->size(); ++i) differs = max_abs((*a)[i] - (*c)[i]) > 0;
  EXPECT_TRUE(differs);
}

// Checked configurations keep obstacle_clearance: a path made with a wide clearance stays wider
// than the default's narrowest gap (dense sampling misses at most a few mm between checks).
TEST(PathSearch, ObstacleClearance) {
  const Problem p = desk();
  const auto narrow = search_path(p, p.goal.q);
  PathSearchOptions o;
  o.obstacle_clearance = 0.12;
  const auto wide = search_path(p, p.goal.q, o);
  ASSERT_TRUE(narrow && wide);
  const double n = dense_clearance(p, *narrow).obstacles, w = dense_clearance(p, *wide).obstacles;
  ASSERT_LT(n, 0.1);
  EXPECT_GT(w, 0.1);
}

TEST(PathTrajectory, PassesEveryWaypointAtRest) {
  const Problem p = desk();
  const auto path = search_path(p, p.goal.q);
  ASSERT_TRUE(path && path->size() >= 3);
  const Trajectory t = path_trajectory(p, *path);
  ASSERT_EQ(t.q.rows(), p.steps + 1);
  EXPECT_LT(max_abs(t.q.row(0).transpose() - p.start_q), 1e-12);
  EXPECT_LT(max_abs(t.q.row(p.steps).transpose() - p.goal.q), 1e-9);
  EXPECT_LT(max_abs(t.qd.row(p.steps)), 1e-9);
  // Each inner waypoint is a state where the trajectory rests.
  for (size_t w = 1; w + 1 < path->size(); ++w) {
    double best = std::numeric_limits<double>::infinity();
    int at = -1;
    for (int k = 0; k <= p.steps; ++k) {
      const double d = max_abs(t.q.row(k).transpose() - (*path)[w]);
      if (d < best) best = d, at = k;
    }
    EXPECT_LT(best, 1e-9) << "waypoint " << w;
    EXPECT_LT(max_abs(t.qd.row(at)), 1e-9) << "waypoint " << w;
  }
}

// A segment's share of the steps follows the time it needs at the velocity limits.
TEST(PathTrajectory, StepsFollowTheSegmentsTimes) {
  Problem p = testing::rr_reach();
  p.steps = 40;
  const Eigen::VectorXd a = p.start_q, b = a + Eigen::VectorXd::Constant(2, 0.1),
                        c = b + Eigen::VectorXd::Constant(2, 0.9);
  const Trajectory t = path_trajectory(p, {a, b, c});
  // 2 steps each, the 36 others split 1 : 9 → b is reached at state 2 + 4 (3.6 rounded up).
  int at = -1;
  for (int k = 0; k <= p.steps; ++k) {
    if (max_abs(t.q.row(k).transpose() - b) < 1e-12) at = k;
  }
  EXPECT_EQ(at, 6);
}

TEST(PathTrajectory, RefusesMoreSegmentsThanFit) {
  Problem p = testing::rr_reach();
  p.steps = 3;
  const Eigen::VectorXd a = p.start_q;
  EXPECT_THROW(path_trajectory(p, {a, a, a}), std::invalid_argument);
  EXPECT_THROW(path_trajectory(p, {a}), std::invalid_argument);
}

TEST(SegmentTrajectory, ViaPointIsTwoEqualSegments) {
  const Problem p = testing::rr_reach();
  const Eigen::VectorXd via = Eigen::Vector2d(0.4, -0.7);
  const Trajectory v = via_point(p, via, p.goal.q);
  const Trajectory s =
      segment_trajectory(p, {p.start_q, via, p.goal.q}, {p.steps / 2, p.steps - p.steps / 2});
  EXPECT_EQ(max_abs(v.q - s.q), 0.0);
  EXPECT_EQ(max_abs(v.qd - s.qd), 0.0);
  EXPECT_LT(max_abs(v.q.row(p.steps / 2).transpose() - via), 1e-12);
  EXPECT_THROW(segment_trajectory(p, {p.start_q, p.goal.q}, {p.steps - 1}), std::invalid_argument);
  EXPECT_THROW(segment_trajectory(p, {p.start_q, via, p.goal.q}, {0, p.steps}),
               std::invalid_argument);
}

// BatchPlannerOptions::path_search: the desk's first attempt starts from the searched path, so
// the plan differs from the one made without the search.
TEST(BatchPlannerOptions, PathSearch) {
  const Problem p = desk();
  const Plan with = BatchPlanner().plan(p);
  BatchPlannerOptions o;
  o.path_search.max_samples = 0;
  const Plan without = BatchPlanner(o).plan(p);
  ASSERT_TRUE(with.success()) << testing::failures(with);
  ASSERT_EQ(with.q.rows(), without.q.rows());
  EXPECT_GT(max_abs(with.q - without.q), 1e-3);
}

}  // namespace
}  // namespace kinograph::planning

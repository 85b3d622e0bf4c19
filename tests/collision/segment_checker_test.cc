// Between-steps checking: the sweep bound, a thin plate the end states straddle, a moving
// obstacle met only mid-segment.
#include "kinograph/collision/segment_checker.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "kinograph/dynamics/kinematics.h"

namespace kinograph::collision {
namespace {

const std::string kRobots = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/";

Eigen::Isometry3d at(double x, double y, double z) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

// Adds obstacle `id` of `shape` at `pose` to `world`.
void add_obstacle(CollisionWorld& world, Shape shape, const Eigen::Isometry3d& pose, int id = 1) {
  Obstacle o;
  o.id = id;
  o.shape = shape;
  o.pose = pose;
  ASSERT_TRUE(world.add_obstacle(o));
}

class RrSegment : public testing::Test {
 protected:
  RrSegment() : model(dynamics::Model::from_urdf_file(kRobots + "rr/rr.urdf")), data(model) {}
  dynamics::Model model;
  dynamics::Data data;
};

// Joint 1 carries the whole arm: its farthest point is the tip sphere's top, 1 + 0.8 + 0.045.
TEST_F(RrSegment, LeverArmsAreTheArmsReach) {
  const SegmentChecker checker(model);
  ASSERT_EQ(checker.lever().size(), 2);
  EXPECT_NEAR(checker.lever()[0], 1.845, 1e-12);
  EXPECT_NEAR(checker.lever()[1], 0.845, 1e-12);
}

// Swinging the upright arm from one side to the other passes through a 5 mm plate above the
// shoulder; both end states are far from it.
TEST_F(RrSegment, FindsThinPlateBetweenClearEndStates) {
  CollisionWorld world(model);
  Obstacle plate;
  plate.id = 1;
  plate.shape = Shape::box(0.005, 0.5, 0.1);
  plate.pose = at(0.0, 0, 1.5);
  ASSERT_TRUE(world.add_obstacle(plate));
  Eigen::VectorXd q0(2), q1(2);
  q0 << -M_PI / 2 + 0.1, 0;
  q1 << M_PI / 2 - 0.1, 0;
  dynamics::forward_kinematics(model, data, q0);
  EXPECT_GT(world.closest(data).distance, 0.3);
  dynamics::forward_kinematics(model, data, q1);
  EXPECT_GT(world.closest(data).distance, 0.3);

  SegmentChecker checker(model);
  const SegmentCheckResult r = checker.check(world, data, q0, q1);
  EXPECT_LT(r.min_distance, -0.03);  // the forearm (r 0.04) cuts the plate
  EXPECT_NEAR(r.s, 0.5, 0.01);
  EXPECT_EQ(r.closest.obstacle, 1);
  // Sampling only the ends would have missed it.
  SegmentChecker coarse(model, {.max_joint_step = 10, .max_sweep_step = 100});
  EXPECT_EQ(coarse.check(world, data, q0, q1).samples, 2);
  EXPECT_GT(coarse.check(world, data, q0, q1).min_distance, 0.3);
}

// A sphere that crosses the arm's path only in the middle of the time interval.
TEST_F(RrSegment, MovingObstacleAtInterpolatedTime) {
  CollisionWorld world(model);
  Obstacle o;
  o.id = 4;
  o.shape = Shape::sphere(0.1);
  o.trajectory = PoseTrajectory({0.0, 1.0, 2.0}, {at(0, 0, 3), at(0, 0, 1.2), at(0, 0, 3)});
  ASSERT_TRUE(world.add_obstacle(o));
  Eigen::VectorXd q0 = Eigen::VectorXd::Zero(2), q1 = Eigen::VectorXd::Zero(2);
  q1[1] = 0.01;  // barely moving: the obstacle's time span drives the sampling
  SegmentChecker checker(model, {.max_time_step = 0.1});
  const SegmentCheckResult r = checker.check(world, data, q0, q1, 0.0, 2.0);
  EXPECT_EQ(r.samples, 21);
  EXPECT_NEAR(r.s, 0.5, 1e-12);
  EXPECT_LT(r.min_distance, -0.1);  // the upright link-1 cylinder is inside the sphere at t = 1
}

// The sampled minimum is within half a sweep step of the minimum found by dense sampling.
TEST_F(RrSegment, CoarseMinimumWithinHalfASweepStepOfDenseMinimum) {
  CollisionWorld world(model);
  Obstacle o;
  o.id = 1;
  o.shape = Shape::sphere(0.05);
  o.pose = at(0.9, 0, 1.3);
  ASSERT_TRUE(world.add_obstacle(o));
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-2, 2);
  const SegmentCheckOptions coarse_opts{.max_joint_step = 10, .max_sweep_step = 0.2};
  const SegmentCheckOptions dense_opts{.max_joint_step = 10, .max_sweep_step = 0.001};
  SegmentChecker coarse(model, coarse_opts), dense(model, dense_opts);
  for (int trial = 0; trial < 30; ++trial) {
    Eigen::VectorXd q0(2), q1(2);
    q0 << u(rng), u(rng);
    q1 << u(rng), u(rng);
    const SegmentCheckResult c = coarse.check(world, data, q0, q1);
    const SegmentCheckResult d = dense.check(world, data, q0, q1);
    EXPECT_LE(d.min_distance, c.min_distance + dense_opts.max_sweep_step / 2);
    EXPECT_GE(d.min_distance, c.min_distance - coarse_opts.max_sweep_step / 2) << trial;
  }
}

// Between consecutive samples no geometry point moves farther than max_sweep_step.
TEST(SegmentChecker, ConsecutiveSamplesRespectSweepBoundOnIiwa) {
  const dynamics::Model model = dynamics::Model::from_urdf_file(kRobots + "iiwa14/iiwa14.urdf");
  dynamics::Data data(model);
  const SegmentCheckOptions opts{.max_joint_step = 1.0, .max_sweep_step = 0.02};
  const SegmentChecker checker(model, opts);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  // Test points: each geometry's centre and six points on its bounding sphere.
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::VectorXd q0(model.nq()), q1(model.nq());
    for (int j = 0; j < model.nq(); ++j) {
      q0[j] = u(rng);
      q1[j] = q0[j] + 0.5 * u(rng);
    }
    const int n = checker.intervals(q0, q1);
    ASSERT_GE(n, 1);
    std::vector<Eigen::Vector3d> prev, cur;
    for (int k = 0; k <= n; ++k) {
      const Eigen::VectorXd q = q0 + (static_cast<double>(k) / n) * (q1 - q0);
      dynamics::forward_kinematics(model, data, q);
      cur.clear();
      for (const auto& g : model.collision) {
        if (g.body < 0) continue;
        const Eigen::Isometry3d T = data.body_pose[g.body] * g.origin;
        const double r = g.size.x();
        for (const Eigen::Vector3d& d :
             {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(r, 0, 0), Eigen::Vector3d(-r, 0, 0),
              Eigen::Vector3d(0, r, 0), Eigen::Vector3d(0, -r, 0), Eigen::Vector3d(0, 0, r),
              Eigen::Vector3d(0, 0, -r)}) {
          cur.push_back(T * d);
        }
      }
      if (k > 0) {
        for (size_t i = 0; i < cur.size(); ++i) {
          EXPECT_LE((cur[i] - prev[i]).norm(), opts.max_sweep_step) << "trial " << trial;
        }
      }
      prev = cur;
    }
  }
}

}  // namespace
}  // namespace kinograph::collision

namespace kinograph::collision {
namespace {

// A random polyline of RR configurations (a path as the validator builds one).
Eigen::MatrixXd random_path(std::mt19937& rng, int rows) {
  std::uniform_real_distribution<double> u(-2, 2), step(-0.3, 0.3);
  Eigen::MatrixXd path(rows, 2);
  path.row(0) << u(rng), u(rng);
  for (int i = 1; i < rows; ++i)
    path.row(i) = path.row(i - 1) + Eigen::RowVector2d(step(rng), step(rng));
  return path;
}

// Conservative advancement against dense sampling of the same polyline: the certified lower
// bound is never above the densely found minimum, the sampled minimum never more than a sweep
// step below... and a penetration dense sampling finds is always found.
TEST_F(RrSegment, PathCheckIsBoundedByDenseSampling) {
  CollisionWorld world(model);
  Obstacle o;
  o.id = 1;
  o.shape = Shape::sphere(0.05);
  o.pose = at(0.9, 0, 1.3);
  ASSERT_TRUE(world.add_obstacle(o));
  std::mt19937 rng(21);
  const SegmentCheckOptions dense_opts{.max_joint_step = 10, .max_sweep_step = 0.0005};
  SegmentChecker checker(model), dense(model, dense_opts);
  int penetrating = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Eigen::MatrixXd path = random_path(rng, 12);
    double dense_min = std::numeric_limits<double>::infinity();
    for (int i = 0; i + 1 < path.rows(); ++i) {
      dense_min = std::min(
          dense_min, dense.check(world, data, path.row(i).transpose(), path.row(i + 1).transpose())
                         .min_distance);
    }
    const PathCheckResult r = checker.check_path(world, data, path);
    EXPECT_LE(r.lower_bound, dense_min + 1e-9) << trial;
    EXPECT_LE(r.lower_bound, r.min_distance);
    EXPECT_GE(r.min_distance, dense_min - dense_opts.max_sweep_step) << trial;
    if (dense_min < 0) {
      ++penetrating;
      EXPECT_LT(r.min_distance, 0) << trial;
    }
  }
  EXPECT_GT(penetrating, 0);  // the seed must exercise the penetrating case
}

// A path sampled from a curve: between two rows a joint that turns around strays from the
// straight segment. Two equal rows about 2 cm from a ball: as a polyline the path keeps its
// distance; with the elbow free to stray 0.05 rad, the tip (0.845 m from the elbow axis) may
// reach the ball, and the sample says so. No stray is the polyline to the bit; a deviation of
// the wrong size is refused.
TEST_F(RrSegment, PathCheckCountsHowFarTheCurveStraysFromItsSegments) {
  CollisionWorld world(model);
  add_obstacle(world, Shape::sphere(0.05), at(0.115, 0, 1.8));
  Eigen::MatrixXd path(2, 2);
  path << 0, 0, 0, 0;
  SegmentChecker checker(model);
  dynamics::forward_kinematics(model, data, path.row(0).transpose());
  const double d0 = world.closest(data).distance;
  ASSERT_GT(d0, 0.015);
  const PathCheckResult polyline = checker.check_path(world, data, path);
  EXPECT_NEAR(polyline.min_distance, d0, 1e-12);
  const PathCheckResult none =
      checker.check_path(world, data, path, {}, 0, Eigen::MatrixXd::Zero(1, 2));
  EXPECT_EQ(none.min_distance, polyline.min_distance);
  EXPECT_EQ(none.samples, polyline.samples);
  const Eigen::MatrixXd elbow = (Eigen::MatrixXd(1, 2) << 0, 0.05).finished();
  const PathCheckResult curve = checker.check_path(world, data, path, {}, 0, elbow);
  EXPECT_NEAR(curve.min_distance, d0 - 0.845 * 0.05, 1e-9);
  EXPECT_LE(curve.lower_bound, curve.min_distance);
  EXPECT_THROW(checker.check_path(world, data, path, {}, 0, Eigen::MatrixXd::Zero(2, 2)),
               std::invalid_argument);
}

// Cubics with a linear acceleration (the planner's interpolant) sampled at six points, each
// segment's deviation h²/8 · max |q̈| at its ends: the walk's certified bound stays below the
// densely sampled minimum of the curve itself, and every penetration of the curve is found.
TEST_F(RrSegment, PathCheckOfACurveIsBoundedByDenseSamplingOfTheCurve) {
  CollisionWorld world(model);
  add_obstacle(world, Shape::sphere(0.05), at(0.9, 0, 1.3));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(-1, 1.5), vel(-2, 2), acc(-30, 30);
  const double T = 0.5;
  const int rows = 6, dense_points = 2000;
  SegmentChecker checker(model);
  int penetrating = 0;
  for (int trial = 0; trial < 60; ++trial) {
    Eigen::Vector2d q0, v0, a0, a1;
    q0 << pos(rng), pos(rng);
    v0 << vel(rng), vel(rng);
    a0 << acc(rng), acc(rng);
    a1 << acc(rng), acc(rng);
    const auto q = [&](double s) -> Eigen::Vector2d {
      return q0 + v0 * s + a0 * s * s / 2 + (a1 - a0) * s * s * s / (6 * T);
    };
    const auto qdd = [&](double s) -> Eigen::Vector2d { return a0 + (a1 - a0) * s / T; };
    const double h = T / (rows - 1);
    Eigen::MatrixXd path(rows, 2), deviation(rows - 1, 2);
    for (int i = 0; i < rows; ++i) path.row(i) = q(i * h).transpose();
    for (int i = 0; i + 1 < rows; ++i) {
      deviation.row(i) =
          (h * h / 8 * qdd(i * h).cwiseAbs().cwiseMax(qdd((i + 1) * h).cwiseAbs())).transpose();
    }
    double dense_min = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= dense_points; ++i) {
      dynamics::forward_kinematics(model, data, q(T * i / dense_points));
      dense_min = std::min(dense_min, world.closest(data).distance);
    }
    const PathCheckResult r = checker.check_path(world, data, path, {}, 0, deviation);
    EXPECT_LE(r.lower_bound, dense_min + 1e-9) << trial;
    if (dense_min < 0) {
      ++penetrating;
      EXPECT_LT(r.min_distance, 0) << trial;
    }
  }
  EXPECT_GT(penetrating, 0);  // the seed must exercise penetrations
}

// A pair's allowance is spent only by the joints that move it: with a ball 3 cm from the upper
// arm and only the elbow swinging, that pair never limits the walk, and the forearm, 0.4 m from
// the ball, needs a handful of samples where one budget for the whole robot takes the upper
// arm's 3 cm for every step.
TEST_F(RrSegment, PathCheckBudgetsEachPairByTheJointsThatMoveIt) {
  CollisionWorld world(model);
  add_obstacle(world, Shape::sphere(0.03), at(0.1, 0, 0.5));
  Eigen::MatrixXd path(2, 2);
  path << 0, -1.5, 0, 1.5;
  SegmentChecker checker(model);
  const PathCheckResult r = checker.check_path(world, data, path);
  EXPECT_NEAR(r.min_distance, 0.03, 1e-9);
  EXPECT_LT(r.samples, 15);
  EXPECT_GT(r.lower_bound, 0.02);
}

// The same on the iiwa with its self pairs, whose walk budgets each pair by the joints that move
// its geometries apart: the certified bound stays below the densely sampled minimum, every
// penetration dense sampling finds is found, with a fraction of its queries.
TEST(IiwaPath, PairByPairWalkIsBoundedByDenseSampling) {
  const dynamics::Model model = dynamics::Model::from_urdf_file(kRobots + "iiwa14/iiwa14.urdf");
  dynamics::Data data(model);
  CollisionWorldOptions opts;
  opts.self_collision = true;
  CollisionWorld world(model, opts);
  add_obstacle(world, Shape::box(0.3, 0.3, 0.3), at(0.45, 0.1, 0.7));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.5, 1.5), step(-0.25, 0.25);
  const SegmentCheckOptions dense_opts{.max_joint_step = 10, .max_sweep_step = 0.002};
  SegmentChecker checker(model), dense(model, dense_opts);
  int penetrating = 0, walk_samples = 0, dense_samples = 0;
  for (int trial = 0; trial < 25; ++trial) {
    Eigen::MatrixXd path(6, model.nq());
    for (int j = 0; j < model.nq(); ++j) path(0, j) = u(rng);
    for (int i = 1; i < path.rows(); ++i) {
      for (int j = 0; j < model.nq(); ++j) path(i, j) = path(i - 1, j) + step(rng);
    }
    double dense_min = std::numeric_limits<double>::infinity();
    for (int i = 0; i + 1 < path.rows(); ++i) {
      const SegmentCheckResult r =
          dense.check(world, data, path.row(i).transpose(), path.row(i + 1).transpose());
      dense_min = std::min(dense_min, r.min_distance);
      dense_samples += r.samples;
    }
    const PathCheckResult r = checker.check_path(world, data, path);
    walk_samples += r.samples;
    EXPECT_TRUE(r.complete);
    EXPECT_LE(r.lower_bound, dense_min + 1e-9) << trial;
    EXPECT_LE(r.lower_bound, r.min_distance);
    EXPECT_GE(r.min_distance, dense_min - 1e-9 - SegmentCheckOptions().max_sweep_step) << trial;
    if (dense_min < 0) {
      ++penetrating;
      EXPECT_LT(r.min_distance, 0) << trial;
    }
  }
  EXPECT_GT(penetrating, 0);  // the seed must exercise the penetrating case
  EXPECT_LT(walk_samples, dense_samples / 3);  // in contact it steps by max_sweep_step
}

// Far from every obstacle a long path costs a handful of queries; the ends are always checked.
TEST_F(RrSegment, PathCheckSkipsClearStretches) {
  CollisionWorld world(model);
  Obstacle o;
  o.id = 1;
  o.shape = Shape::sphere(0.05);
  o.pose = at(0, 0, -1.5);  // below the base, out of reach
  ASSERT_TRUE(world.add_obstacle(o));
  Eigen::MatrixXd path(101, 2);
  for (int i = 0; i <= 100; ++i) path.row(i) << -1.0 + 0.02 * i, 0.3;
  SegmentChecker checker(model);
  const PathCheckResult r = checker.check_path(world, data, path);
  const int dense_samples = checker.intervals(path.row(0).transpose(), path.row(100).transpose());
  EXPECT_LT(r.samples, dense_samples / 10);
  EXPECT_GE(r.samples, 2);
  EXPECT_GT(r.lower_bound, 0);
  dynamics::forward_kinematics(model, data, path.row(100).transpose());
  EXPECT_GE(world.closest(data).distance, r.min_distance);
}

// A path that sweeps further than max_path_samples queries can walk stops there and says where,
// instead of walking for ever (a plan file with q = 1e308).
TEST_F(RrSegment, PathCheckStopsAtItsQueryBound) {
  CollisionWorld world(model);
  Obstacle o;
  o.id = 1;
  o.shape = Shape::sphere(0.05);
  o.pose = at(0, 0, -1.5);  // below the base: every sample's budget is about a metre
  ASSERT_TRUE(world.add_obstacle(o));
  Eigen::MatrixXd path(3, 2);
  path << 0, 0, 1e6, 0, 0, 0;
  SegmentCheckOptions options;
  options.max_path_samples = 1000;
  options.max_path_sweep = std::numeric_limits<double>::infinity();
  SegmentChecker checker(model, options);
  const PathCheckResult r = checker.check_path(world, data, path);
  EXPECT_FALSE(r.complete);
  EXPECT_EQ(r.samples, 1000);
  EXPECT_EQ(r.stopped_segment, 0);
  EXPECT_GT(r.stopped_s, 0);
  EXPECT_LT(r.stopped_s, 1e-2);
  // The same path within the bound is walked whole.
  path << 0, 0, 1, 0, 0, 0;
  EXPECT_TRUE(checker.check_path(world, data, path).complete);
}

// A path whose geometry sweeps further than max_path_sweep stops once it has, long before the
// query bound (a plan file with q̇ = 1e7: every query there is wasted).
TEST_F(RrSegment, PathCheckStopsAtItsSweepBound) {
  CollisionWorld world(model);
  Obstacle o;
  o.id = 1;
  o.shape = Shape::sphere(0.05);
  o.pose = at(0, 0, -1.5);
  ASSERT_TRUE(world.add_obstacle(o));
  Eigen::MatrixXd path(3, 2);
  path << 0, 0, 1e6, 0, 0, 0;
  SegmentChecker checker(model, {.max_path_sweep = 50});
  const PathCheckResult r = checker.check_path(world, data, path);
  EXPECT_FALSE(r.complete);
  EXPECT_GT(r.swept, 50);
  EXPECT_LT(r.swept, 52);  // stopped at the first sample past the bound (steps under 1 m)
  EXPECT_LT(r.samples, 1000);
  EXPECT_EQ(r.stopped_segment, 0);
  // Within the bound the same path is walked whole, and its sweep counted.
  path << 0, 0, 1, 0, 0, 0;
  const PathCheckResult whole = checker.check_path(world, data, path);
  EXPECT_TRUE(whole.complete);
  EXPECT_NEAR(whole.swept, 2 * checker.lever()[0], 1e-9);
}

// With stop_below the walk ends at its first sample below it: a path that never comes that
// close is walked exactly as without it; one that does ends there, with fewer queries, a
// minimum below the threshold and the walk counted complete (no budget ran out).
TEST_F(RrSegment, PathCheckStopsAtItsFirstSampleBelowStopBelow) {
  CollisionWorld world(model);
  add_obstacle(world, Shape::sphere(0.05), at(0.9, 0, 1.3));
  std::mt19937 rng(21);
  SegmentChecker full(model), first(model, {.stop_below = 0.0});
  int stopped = 0, shorter = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Eigen::MatrixXd path = random_path(rng, 12);
    const PathCheckResult all = full.check_path(world, data, path);
    const PathCheckResult r = first.check_path(world, data, path);
    EXPECT_FALSE(all.stopped_below);
    EXPECT_TRUE(r.complete);
    if (all.min_distance >= 0) {
      EXPECT_FALSE(r.stopped_below) << trial;
      EXPECT_EQ(r.samples, all.samples) << trial;
      EXPECT_EQ(r.min_distance, all.min_distance) << trial;
      EXPECT_EQ(r.lower_bound, all.lower_bound) << trial;
      continue;
    }
    ++stopped;
    EXPECT_TRUE(r.stopped_below) << trial;
    EXPECT_LT(r.min_distance, 0) << trial;
    EXPECT_LE(r.samples, all.samples) << trial;
    // The same walk up to there: its first sample below, never past the full walk's least.
    EXPECT_GE(r.min_distance, all.min_distance) << trial;
    EXPECT_TRUE(r.segment < all.segment || (r.segment == all.segment && r.s <= all.s)) << trial;
    shorter += r.samples < all.samples;
  }
  EXPECT_GT(stopped, 0);  // the seed must exercise both cases
  EXPECT_LT(stopped, 40);
  EXPECT_GT(shorter, 0);
}

// Moving obstacles: samples at most max_time_step apart in time, and the sphere that passes
// through the arm mid-path is found.
TEST_F(RrSegment, PathCheckFollowsMovingObstaclesInTime) {
  CollisionWorld world(model);
  Obstacle o;
  o.id = 4;
  o.shape = Shape::sphere(0.1);
  o.trajectory = PoseTrajectory({0.0, 1.0, 2.0}, {at(0, 0, 3), at(0, 0, 1.2), at(0, 0, 3)});
  ASSERT_TRUE(world.add_obstacle(o));
  Eigen::MatrixXd path = Eigen::MatrixXd::Zero(3, 2);
  path(2, 1) = 0.01;
  SegmentChecker checker(model, {.max_time_step = 0.1});
  const PathCheckResult r = checker.check_path(world, data, path, {0.0, 1.0, 2.0});
  EXPECT_GE(r.samples, 21);
  EXPECT_LT(r.min_distance, -0.1);
  // Found while the sphere overlaps the arm (it reaches the tip at t ≈ 0.59 and leaves at 1.41).
  const double t = r.segment + r.s;
  EXPECT_GT(t, 0.55);
  EXPECT_LT(t, 1.45);
}

}  // namespace
}  // namespace kinograph::collision

// CollisionWorld on real robots: known configurations against obstacles at known distances,
// add/move/remove by id, moving obstacles, and culling that changes nothing.
#include "kinograph/collision/collision_world.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
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

Obstacle make_obstacle(int id, Shape shape, const Eigen::Isometry3d& pose) {
  Obstacle o;
  o.id = id;
  o.shape = std::move(shape);
  o.pose = pose;
  return o;
}

// Index into model.collision of the sphere of this radius on this link.
int sphere_on(const dynamics::Model& model, const std::string& link, double radius) {
  const int body = model.body_index(link);
  for (size_t i = 0; i < model.collision.size(); ++i) {
    const auto& g = model.collision[i];
    if (g.body == body && g.shape == dynamics::Geometry::Shape::kSphere &&
        std::abs(g.size.x() - radius) < 1e-12) {
      return static_cast<int>(i);
    }
  }
  return -1;
}

const Proximity* closest_of(std::span<const Proximity> ps) {
  const Proximity* best = nullptr;
  for (const Proximity& p : ps) {
    if (best == nullptr || p.distance < best->distance) best = &p;
  }
  return best;
}

class RrWorld : public testing::Test {
 protected:
  RrWorld() : model(dynamics::Model::from_urdf_file(kRobots + "rr/rr.urdf")), data(model) {}
  void fk(double q1, double q2) {
    Eigen::VectorXd q(2);
    q << q1, q2;
    dynamics::forward_kinematics(model, data, q);
  }
  dynamics::Model model;
  dynamics::Data data;
};

// At q = (π/2, 0) the arm lies along +x; its tip sphere (r 0.045) is centred at x = 1.8.
TEST_F(RrWorld, ArmAlongXAgainstSphere) {
  CollisionWorldOptions opts;
  opts.query_distance = 0.5;
  CollisionWorld world(model, opts);
  ASSERT_TRUE(world.add_obstacle(make_obstacle(7, Shape::sphere(0.1), at(2.2, 0, 0))));
  fk(M_PI / 2, 0);
  const auto ps = world.query(data);
  const Proximity* p = closest_of(ps);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->robot_geom, sphere_on(model, "link2", 0.045));
  EXPECT_EQ(p->obstacle, 7);
  EXPECT_NEAR(p->distance, 2.2 - 1.8 - 0.045 - 0.1, 1e-9);
  EXPECT_LT((p->point_on_robot - Eigen::Vector3d(1.845, 0, 0)).norm(), 1e-9);
  EXPECT_LT((p->point_on_obstacle - Eigen::Vector3d(2.1, 0, 0)).norm(), 1e-9);
  EXPECT_LT((p->normal - Eigen::Vector3d(-1, 0, 0)).norm(), 1e-9);
  // Every reported pair is within the query distance, and the link-2 cylinder's flat end is
  // reported at its closed-form 0.3.
  bool saw_cylinder = false;
  for (const Proximity& q : ps) {
    EXPECT_LE(q.distance, world.options().query_distance);
    if (model.collision[q.robot_geom].shape == dynamics::Geometry::Shape::kCylinder &&
        model.collision[q.robot_geom].body == model.body_index("link2")) {
      saw_cylinder = true;
      EXPECT_NEAR(q.distance, 0.3, 1e-9);
    }
  }
  EXPECT_TRUE(saw_cylinder);
}

// At q = (π/2, −π/2) the forearm stands up from (1, 0, 0); a sphere beside it at x = 1.5.
TEST_F(RrWorld, ElbowBentAgainstSphereBesideForearm) {
  CollisionWorld world(model);
  ASSERT_TRUE(world.add_obstacle(make_obstacle(1, Shape::sphere(0.1), at(1.5, 0, 0.4))));
  fk(M_PI / 2, -M_PI / 2);
  const Proximity p = world.closest(data);
  EXPECT_NEAR(p.distance, 0.5 - 0.04 - 0.1, 1e-9);
  EXPECT_EQ(model.collision[p.robot_geom].shape, dynamics::Geometry::Shape::kCylinder);
  // GJK stops when the distance has converged; witness points on a flat side converge only to
  // about the square root of that tolerance.
  EXPECT_LT((p.point_on_robot - Eigen::Vector3d(1.04, 0, 0.4)).norm(), 1e-6);
  EXPECT_LT((p.normal - Eigen::Vector3d(-1, 0, 0)).norm(), 1e-6);
}

// Upright arm pushed into a box overhead: penetration depth from the tip sphere.
TEST_F(RrWorld, UprightArmPenetratingBox) {
  CollisionWorld world(model);
  // Box bottom face at z = 1.8: the tip sphere (top at 1.845) is 0.045 deep.
  ASSERT_TRUE(world.add_obstacle(make_obstacle(3, Shape::box(1, 1, 0.4), at(0, 0, 2.0))));
  fk(0, 0);
  const Proximity p = world.closest(data);
  EXPECT_EQ(p.robot_geom, sphere_on(model, "link2", 0.045));
  EXPECT_NEAR(p.distance, -0.045, 1e-9);
  EXPECT_LT((p.normal - Eigen::Vector3d(0, 0, -1)).norm(), 1e-9);
}

TEST_F(RrWorld, AddMoveRemoveById) {
  CollisionWorld world(model);
  fk(0, 0);
  EXPECT_TRUE(world.query(data).empty());
  EXPECT_TRUE(std::isinf(world.closest(data).distance));
  ASSERT_TRUE(world.add_obstacle(make_obstacle(10, Shape::sphere(0.1), at(0.3, 0, 1.0))));
  ASSERT_TRUE(world.add_obstacle(make_obstacle(20, Shape::sphere(0.1), at(-0.35, 0, 0.5))));
  const Status dup = world.add_obstacle(make_obstacle(10, Shape::sphere(1), at(0, 0, 0)));
  EXPECT_FALSE(dup.ok);
  EXPECT_NE(dup.reason.find("10"), std::string::npos);
  EXPECT_EQ(world.num_obstacles(), 2);

  auto min_for = [&](int id) {
    double best = INFINITY;
    for (const Proximity& p : world.query(data)) {
      if (p.obstacle == id) best = std::min(best, p.distance);
    }
    return best;
  };
  // Link-1 cylinder (r 0.04, along z from 0 to 1) against each sphere's side.
  EXPECT_NEAR(min_for(10), 0.3 - 0.05 - 0.1, 1e-9);  // the elbow sphere (r 0.05) at z = 1
  EXPECT_NEAR(min_for(20), 0.35 - 0.04 - 0.1, 1e-9);

  ASSERT_TRUE(world.move_obstacle(20, at(-0.25, 0, 0.5)));
  EXPECT_NEAR(min_for(20), 0.25 - 0.04 - 0.1, 1e-9);
  EXPECT_NEAR(min_for(10), 0.15, 1e-9);  // untouched

  ASSERT_TRUE(world.remove_obstacle(10));
  EXPECT_FALSE(world.remove_obstacle(10).ok);
  EXPECT_FALSE(world.move_obstacle(10, at(0, 0, 0)).ok);
  EXPECT_EQ(world.find_obstacle(10), nullptr);
  ASSERT_NE(world.find_obstacle(20), nullptr);
  EXPECT_TRUE(std::isinf(min_for(10)));
  EXPECT_NEAR(min_for(20), 0.11, 1e-9);
  world.clear_obstacles();
  EXPECT_TRUE(world.query(data).empty());
}

TEST(PoseTrajectory, InterpolatesLinearlyAndSlerpsAndHoldsEnds) {
  Eigen::Isometry3d a = at(0, 0, 0), b = at(2, -4, 6);
  b.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Isometry3d c = at(2, -4, 7);
  const PoseTrajectory traj({1.0, 3.0, 4.0}, {a, b, c});
  const Eigen::Isometry3d mid = traj.at(1.5);  // a quarter of the way from a to b
  EXPECT_LT((mid.translation() - Eigen::Vector3d(0.5, -1, 1.5)).norm(), 1e-12);
  const Eigen::Matrix3d expected_R =
      Eigen::AngleAxisd(M_PI / 8, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_LT((mid.linear() - expected_R).norm(), 1e-12);
  EXPECT_LT((traj.at(3.5).translation() - Eigen::Vector3d(2, -4, 6.5)).norm(), 1e-12);
  EXPECT_LT((traj.at(-10).matrix() - a.matrix()).norm(), 1e-12);
  EXPECT_LT((traj.at(10).matrix() - c.matrix()).norm(), 1e-12);
  EXPECT_LT((traj.at(3.0).matrix() - b.matrix()).norm(), 1e-12);

  EXPECT_THROW(PoseTrajectory({0.0, 1.0}, {a}), std::invalid_argument);
  EXPECT_THROW(PoseTrajectory({0.0, 0.0}, {a, b}), std::invalid_argument);
  EXPECT_THROW(PoseTrajectory({}, {}), std::invalid_argument);
}

TEST_F(RrWorld, MovingObstacleIsQueriedAtTime) {
  CollisionWorld world(model);
  Obstacle o = make_obstacle(5, Shape::sphere(0.1), at(0, 0, 0));
  // Passes the upright arm's link-1 cylinder from x = 1.14 (t = 0) to x = 0.14 (t = 2).
  o.trajectory = PoseTrajectory({0.0, 2.0}, {at(1.14, 0, 0.5), at(0.14, 0, 0.5)});
  ASSERT_TRUE(world.add_obstacle(o));
  fk(0, 0);
  EXPECT_NEAR(world.closest(data, 0.0).distance, 1.0, 1e-9);
  EXPECT_NEAR(world.closest(data, 1.0).distance, 0.5, 1e-9);
  EXPECT_NEAR(world.closest(data, 1.9).distance, 0.05, 1e-9);
  EXPECT_NEAR(world.closest(data, 5.0).distance, 0.0, 1e-9);
  // A fixed pose replaces the trajectory.
  ASSERT_TRUE(world.move_obstacle(5, at(0.34, 0, 0.5)));
  EXPECT_NEAR(world.closest(data, 1.0).distance, 0.2, 1e-9);
  ASSERT_TRUE(world.set_obstacle_trajectory(5, PoseTrajectory({0.0}, {at(0.44, 0, 0.5)})));
  EXPECT_NEAR(world.closest(data, 1.0).distance, 0.3, 1e-9);
}

// Random iiwa configurations and obstacles of every primitive kind: bounding-sphere culling
// and best-so-far culling give exactly the brute-force answers.
TEST(CollisionWorldCulling, MatchesBruteForceOnIiwa) {
  const dynamics::Model model = dynamics::Model::from_urdf_file(kRobots + "iiwa14/iiwa14.urdf");
  dynamics::Data data(model);
  CollisionWorldOptions culled_opts;
  culled_opts.query_distance = 0.25;
  culled_opts.self_collision = true;
  CollisionWorldOptions brute_opts = culled_opts;
  brute_opts.cull = false;
  CollisionWorld culled(model, culled_opts), brute(model, brute_opts);

  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-1, 1), pos(0.1, 0.5);
  // Small and thin obstacles, and a large box the arm often reaches deep into.
  const Shape shapes[] = {Shape::box(0.3, 0.2, 0.4),  Shape::sphere(0.12),
                          Shape::cylinder(0.08, 0.5), Shape::capsule(0.06, 0.3),
                          Shape::box(0.05, 1.0, 1.0), Shape::box(0.6, 0.6, 0.6)};
  for (int id = 0; id < 6; ++id) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() =
        Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
    pose.translation() = Eigen::Vector3d(0.7 * u(rng), 0.7 * u(rng), 0.6 + 0.5 * u(rng));
    ASSERT_TRUE(culled.add_obstacle(make_obstacle(id, shapes[id], pose)));
    ASSERT_TRUE(brute.add_obstacle(make_obstacle(id, shapes[id], pose)));
  }
  int total_reported = 0;
  for (int trial = 0; trial < 150; ++trial) {
    Eigen::VectorXd q(model.nq());
    for (int j = 0; j < model.nq(); ++j) q[j] = 2.0 * u(rng);
    dynamics::forward_kinematics(model, data, q);
    const auto a = culled.query(data);
    std::vector<Proximity> b(brute.query(data).begin(), brute.query(data).end());
    ASSERT_EQ(a.size(), b.size()) << "trial " << trial;
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].robot_geom, b[i].robot_geom);
      EXPECT_EQ(a[i].obstacle, b[i].obstacle);
      EXPECT_EQ(a[i].other_geom, b[i].other_geom);
      EXPECT_EQ(a[i].distance, b[i].distance);
    }
    total_reported += static_cast<int>(a.size());
    // closest() against the minimum over every pair computed without any query distance.
    const auto all = brute.query(data, 0, INFINITY);
    const Proximity* best = closest_of(all);
    ASSERT_NE(best, nullptr);
    EXPECT_EQ(culled.closest(data).distance, best->distance);
  }
  EXPECT_GT(total_reported, 100);  // the scene is close enough for the comparison to matter
}

// closest()'s per-pair bounds on the same kind of scene: never above the pair's distance, equal
// to it where closest() measured it, and in closest_pairs() order.
TEST(CollisionWorldCulling, PairBoundsAreLowerBoundsOfEachPair) {
  const dynamics::Model model = dynamics::Model::from_urdf_file(kRobots + "iiwa14/iiwa14.urdf");
  dynamics::Data data(model);
  CollisionWorldOptions culled_opts;
  culled_opts.self_collision = true;
  CollisionWorldOptions brute_opts = culled_opts;
  brute_opts.cull = false;
  CollisionWorld culled(model, culled_opts), brute(model, brute_opts);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const Shape shapes[] = {Shape::box(0.3, 0.2, 0.4), Shape::sphere(0.12), Shape::box(0.6, 0.6, 0.6)};
  for (int id = 0; id < 3; ++id) {
    const Eigen::Isometry3d pose = at(0.6 * u(rng), 0.6 * u(rng), 0.6 + 0.4 * u(rng));
    ASSERT_TRUE(culled.add_obstacle(make_obstacle(id, shapes[id], pose)));
    ASSERT_TRUE(brute.add_obstacle(make_obstacle(id, shapes[id], pose)));
  }
  std::vector<CollisionWorld::PairIndex> pairs;
  culled.closest_pairs(pairs);
  int measured = 0, bounded = 0;
  for (int trial = 0; trial < 100; ++trial) {
    Eigen::VectorXd q(model.nq());
    for (int j = 0; j < model.nq(); ++j) q[j] = 2.0 * u(rng);
    dynamics::forward_kinematics(model, data, q);
    const Proximity best = culled.closest(data);
    (void)brute.closest(data);
    const auto bounds = culled.pair_bounds();
    const auto exact = brute.pair_bounds();
    ASSERT_EQ(bounds.size(), pairs.size());
    ASSERT_EQ(exact.size(), pairs.size());
    for (size_t k = 0; k < pairs.size(); ++k) {
      EXPECT_LE(bounds[k], exact[k] + 1e-12) << "trial " << trial << " pair " << k;
      (bounds[k] == exact[k] ? measured : bounded) += 1;
    }
    // The closest pair's entry is its distance.
    const auto is_best = [&](const CollisionWorld::PairIndex& pr) {
      return pr.self ? best.obstacle < 0 && pr.a == best.robot_geom && pr.b == best.other_geom
                     : best.obstacle == pr.b && pr.a == best.robot_geom;
    };
    const auto it = std::find_if(pairs.begin(), pairs.end(), is_best);
    ASSERT_NE(it, pairs.end());
    EXPECT_EQ(bounds[static_cast<size_t>(it - pairs.begin())], best.distance);
  }
  EXPECT_GT(bounded, 100);  // most pairs are culled by their bounds, not measured
  EXPECT_GT(measured, 100);
}

TEST(CollisionWorldSelf, NonAdjacentPairsOnlyAndExclusions) {
  const dynamics::Model model = dynamics::Model::from_urdf_file(kRobots + "rr/rr.urdf");
  dynamics::Data data(model);
  CollisionWorldOptions opts;
  opts.self_collision = true;
  opts.query_distance = INFINITY;
  CollisionWorld world(model, opts);
  Eigen::VectorXd q(2);
  q << 0.3, 3.0;  // the forearm folded back along the upper arm
  dynamics::forward_kinematics(model, data, q);
  // Base (-1) and link2 are the only non-adjacent bodies; base has one geometry, link2 three.
  const auto ps = world.query(data);
  ASSERT_EQ(ps.size(), 3u);
  for (const Proximity& p : ps) {
    EXPECT_TRUE(p.is_self_collision());
    EXPECT_EQ(p.obstacle, -1);
    const int b1 = model.collision[p.robot_geom].body, b2 = model.collision[p.other_geom].body;
    EXPECT_EQ(std::min(b1, b2), -1);
    EXPECT_EQ(std::max(b1, b2), model.body_index("link2"));
  }
  opts.self_collision_excluded = {{model.body_index("link2"), -1}};
  CollisionWorld excluded(model, opts);
  EXPECT_TRUE(excluded.query(data).empty());
}

}  // namespace
}  // namespace kinograph::collision

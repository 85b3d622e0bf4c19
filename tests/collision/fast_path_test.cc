// The fast paths of CollisionWorld (culling without square roots, geometry poses made only for
// pairs that survive culling, closest() in order of lower bounds) against a plain reference: every
// (robot geometry, obstacle) pair through pair_distance at poses made here from the forward
// kinematics. Answers must agree bit for bit, including pairs exactly at the query-distance cut-off
// and penetrating pairs.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "kinograph/collision/collision_world.h"
#include "kinograph/collision/convex_shape.h"
#include "kinograph/collision/pair_distance.h"
#include "kinograph/dynamics/kinematics.h"

namespace kinograph::collision {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Obstacle box_at(int id, double sx, double sy, double sz, double x, double y, double z) {
  Obstacle o;
  o.id = id;
  o.shape = Shape::box(sx, sy, sz);
  o.pose.translation() = Eigen::Vector3d(x, y, z);
  return o;
}

// The desk of robots/scenes/iiwa_desk.yaml: tabletop and four legs.
std::vector<Obstacle> desk_scene() {
  return {box_at(0, 0.5, 1.0, 0.04, 0.75, 0, 0.64), box_at(1, 0.04, 0.04, 0.62, 0.52, 0.48, 0.31),
          box_at(2, 0.04, 0.04, 0.62, 0.52, -0.48, 0.31),
          box_at(3, 0.04, 0.04, 0.62, 0.98, 0.48, 0.31),
          box_at(4, 0.04, 0.04, 0.62, 0.98, -0.48, 0.31)};
}

class CollisionFastPath : public testing::Test {
 protected:
  CollisionFastPath()
      : model(dynamics::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) +
                                              "/robots/iiwa14/iiwa14.urdf")),
        data(model),
        obstacles(desk_scene()) {
    for (const Obstacle& o : obstacles) shapes.push_back(std::make_unique<ConvexShape>(o.shape));
  }

  Eigen::VectorXd random_q(std::mt19937& rng) const {
    Eigen::VectorXd q(model.nq());
    for (int j = 0; j < model.nq(); ++j) {
      const auto& lim = model.bodies[j].limits;
      q[j] = std::uniform_real_distribution<double>(lim.lower, lim.upper)(rng);
    }
    return q;
  }

  // Every moving robot geometry against `only` (or every obstacle when -1), in query() order,
  // at most query_distance away.
  std::vector<Proximity> reference(const CollisionWorld& world, double query_distance,
                                   int only = -1) const {
    std::vector<Proximity> out;
    for (int g = 0; g < static_cast<int>(model.collision.size()); ++g) {
      const dynamics::Geometry& geom = model.collision[g];
      if (geom.body < 0) continue;
      const Eigen::Isometry3d pose = data.body_pose[geom.body] * geom.origin;
      for (size_t o = 0; o < obstacles.size(); ++o) {
        if (only >= 0 && static_cast<int>(o) != only) continue;
        const PairDistance d =
            pair_distance(world.robot_shape(g), pose, *shapes[o], obstacles[o].pose);
        if (!d.valid || d.distance > query_distance) continue;
        Proximity p;
        p.robot_geom = g;
        p.obstacle = obstacles[o].id;
        p.distance = d.distance;
        p.point_on_robot = d.point_on_a;
        p.point_on_obstacle = d.point_on_b;
        p.normal = d.normal;
        out.push_back(p);
      }
    }
    return out;
  }

  dynamics::Model model;
  dynamics::Data data;
  std::vector<Obstacle> obstacles;
  std::vector<std::unique_ptr<ConvexShape>> shapes;
};

void expect_same(std::span<const Proximity> a, const std::vector<Proximity>& b,
                 const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (size_t i = 0; i < a.size(); ++i) {
    SCOPED_TRACE(what + " pair " + std::to_string(i));
    EXPECT_EQ(a[i].robot_geom, b[i].robot_geom);
    EXPECT_EQ(a[i].obstacle, b[i].obstacle);
    EXPECT_EQ(a[i].other_geom, b[i].other_geom);
    EXPECT_EQ(a[i].distance, b[i].distance);
    EXPECT_EQ(a[i].point_on_robot, b[i].point_on_robot);
    EXPECT_EQ(a[i].point_on_obstacle, b[i].point_on_obstacle);
    EXPECT_EQ(a[i].normal, b[i].normal);
  }
}

// One world with the whole desk (batch planner) and one world per desk part (incremental
// planner) against the reference on random configurations.
TEST_F(CollisionFastPath, QueriesMatchPairwiseReferenceBitForBit) {
  CollisionWorldOptions opts;  // defaults: query distance 0.3 m, culling
  CollisionWorld all(model, opts);
  std::vector<std::unique_ptr<CollisionWorld>> single;
  for (const Obstacle& o : obstacles) {
    ASSERT_TRUE(all.add_obstacle(o));
    single.push_back(std::make_unique<CollisionWorld>(model, opts));
    ASSERT_TRUE(single.back()->add_obstacle(o));
  }
  std::mt19937 rng(7);
  int reported = 0, penetrating = 0;
  for (int trial = 0; trial < 400; ++trial) {
    dynamics::forward_kinematics(model, data, random_q(rng));
    const std::vector<Proximity> ref = reference(all, 0.3);
    const std::string what = "trial " + std::to_string(trial);
    expect_same(all.query(data), ref, what);
    expect_same(all.query(data), ref, what + " repeated");
    for (size_t o = 0; o < single.size(); ++o) {
      expect_same(single[o]->query(data), reference(all, 0.3, static_cast<int>(o)),
                  what + " single world " + std::to_string(o));
    }
    reported += static_cast<int>(ref.size());
    for (const Proximity& p : ref) penetrating += p.distance < 0;
  }
  EXPECT_GT(reported, 200);
  EXPECT_GT(penetrating, 10);  // random configurations reach into the desk
}

// A query distance equal to a pair's distance reports it; the next smaller double does not.
TEST_F(CollisionFastPath, PairsExactlyAtTheCutOff) {
  CollisionWorldOptions opts;
  CollisionWorld world(model, opts);
  for (const Obstacle& o : obstacles) ASSERT_TRUE(world.add_obstacle(o));
  std::mt19937 rng(11);
  int checked = 0;
  for (int trial = 0; trial < 300; ++trial) {
    dynamics::forward_kinematics(model, data, random_q(rng));
    const std::vector<Proximity> all = reference(world, kInf);
    for (const Proximity& p : all) {
      if (std::abs(p.distance) > 0.3) continue;
      const double below = std::nextafter(p.distance, -kInf);
      expect_same(world.query(data, 0, p.distance), reference(world, p.distance),
                  "at " + std::to_string(p.distance));
      expect_same(world.query(data, 0, below), reference(world, below),
                  "below " + std::to_string(p.distance));
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

// Self pairs and the floor (a 100 m slab whose bounding sphere says nothing; the link and
// geometry capsules decide) with the query distance exactly at each near pair's distance and one
// double below, and the cut-off 1 mm either side: the culled world reports exactly the pairs
// (and bits) of a world that runs GJK on every pair.
TEST_F(CollisionFastPath, SelfPairsAndTheFloorAtTheCutOff) {
  CollisionWorldOptions opts;
  opts.self_collision = true;
  opts.self_collision_excluded = {{4, 6}};  // the iiwa's wrist pair, as its SRDF
  CollisionWorldOptions brute_opts = opts;
  brute_opts.cull = false;
  CollisionWorld fast(model, opts), brute(model, brute_opts);
  Obstacle floor = box_at(-7, 100, 100, 1, 0, 0, -0.5);
  ASSERT_TRUE(fast.add_obstacle(floor));
  ASSERT_TRUE(brute.add_obstacle(floor));
  std::mt19937 rng(13);
  int self_checked = 0, floor_checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    dynamics::forward_kinematics(model, data, random_q(rng));
    const std::vector<Proximity> all(brute.query(data, 0, kInf).begin(),
                                     brute.query(data, 0, kInf).end());
    for (const Proximity& p : all) {
      if (p.distance > 0.1) continue;
      for (const double cut :
           {p.distance, std::nextafter(p.distance, -kInf), p.distance + 1e-3, p.distance - 1e-3}) {
        const std::vector<Proximity> ref(brute.query(data, 0, cut).begin(),
                                         brute.query(data, 0, cut).end());
        expect_same(fast.query(data, 0, cut), ref, "trial " + std::to_string(trial));
      }
      (p.is_self_collision() ? self_checked : floor_checked)++;
    }
    const Proximity a = fast.closest(data), b = brute.closest(data);
    EXPECT_EQ(a.distance, b.distance);
    EXPECT_EQ(a.robot_geom, b.robot_geom);
    EXPECT_EQ(a.other_geom, b.other_geom);
  }
  EXPECT_GT(self_checked, 100);
  EXPECT_GT(floor_checked, 20);
}

// closest() visits pairs in order of their bounds; it must give the brute-force minimum and,
// among equals, the same pair as the brute-force order.
TEST_F(CollisionFastPath, ClosestMatchesBruteForce) {
  CollisionWorldOptions opts;
  opts.self_collision = true;
  CollisionWorldOptions brute_opts = opts;
  brute_opts.cull = false;
  CollisionWorld fast(model, opts), brute(model, brute_opts);
  for (const Obstacle& o : obstacles) {
    ASSERT_TRUE(fast.add_obstacle(o));
    ASSERT_TRUE(brute.add_obstacle(o));
  }
  std::mt19937 rng(5);
  int penetrating = 0;
  for (int trial = 0; trial < 300; ++trial) {
    dynamics::forward_kinematics(model, data, random_q(rng));
    const Proximity a = fast.closest(data), b = brute.closest(data);
    SCOPED_TRACE("trial " + std::to_string(trial));
    EXPECT_EQ(a.distance, b.distance);
    EXPECT_EQ(a.robot_geom, b.robot_geom);
    EXPECT_EQ(a.obstacle, b.obstacle);
    EXPECT_EQ(a.other_geom, b.other_geom);
    EXPECT_EQ(a.point_on_robot, b.point_on_robot);
    EXPECT_EQ(a.normal, b.normal);
    penetrating += a.distance < 0;
  }
  EXPECT_GT(penetrating, 5);
}

// A world that has lived through obstacle changes and interleaved queries at changing times
// (geometry poses are made lazily, stamped per query) answers as a world built afresh.
TEST_F(CollisionFastPath, LongLivedWorldAnswersAsAFreshOne) {
  CollisionWorldOptions opts;
  CollisionWorld live(model, opts);
  std::vector<Obstacle> current = obstacles;
  for (const Obstacle& o : current) ASSERT_TRUE(live.add_obstacle(o));
  // A ball sweeping through the workspace, so the answer depends on time.
  Obstacle ball;
  ball.id = 9;
  ball.shape = Shape::sphere(0.15);
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity(), b = a;
  a.translation() = Eigen::Vector3d(0.4, -0.4, 0.6);
  b.translation() = Eigen::Vector3d(0.4, 0.4, 0.9);
  ball.trajectory = PoseTrajectory({0.0, 1.0}, {a, b});
  ASSERT_TRUE(live.add_obstacle(ball));
  current.push_back(ball);

  std::mt19937 rng(3);
  std::vector<Eigen::VectorXd> qs;
  for (int i = 0; i < 24; ++i) qs.push_back(random_q(rng));
  int reported = 0;
  auto compare = [&](const std::string& what) {
    for (int pass = 0; pass < 3; ++pass) {
      for (size_t i = 0; i < qs.size(); ++i) {
        dynamics::forward_kinematics(model, data, qs[i]);
        const double t = 0.1 * static_cast<double>(i % 4) + 0.05 * (pass == 2);
        CollisionWorld fresh_world(model, opts);
        for (const Obstacle& o : current) EXPECT_TRUE(fresh_world.add_obstacle(o));
        const auto answer = fresh_world.query(data, t);
        const std::vector<Proximity> fresh(answer.begin(), answer.end());
        expect_same(live.query(data, t), fresh,
                    what + " pass " + std::to_string(pass) + " config " + std::to_string(i));
        reported += static_cast<int>(fresh.size());
      }
    }
  };
  compare("initial");
  Eigen::Isometry3d raised = obstacles[0].pose;
  raised.translation().z() += 0.05;
  ASSERT_TRUE(live.move_obstacle(0, raised));
  current[0].pose = raised;
  compare("tabletop moved");
  ASSERT_TRUE(live.remove_obstacle(9));
  current.pop_back();
  compare("ball removed");
  EXPECT_GT(reported, 100);
}

}  // namespace
}  // namespace kinograph::collision

// Goal sampler: seeded and reproducible; every goal within the shrunk limits, inside the region,
// clear of obstacles by ε (checked with an independent CollisionWorld) and of itself.
#include "kinograph/planning/goal_sampler.h"

#include <gtest/gtest.h>

#include "kinograph/collision/collision_world.h"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/io/scene.h"

namespace kinograph::planning {
namespace {

const std::string kSceneDir = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/";

GoalSamplerOptions iiwa_options(std::uint64_t seed) {
  GoalSamplerOptions o;
  o.seed = seed;
  o.self_collision_excluded = {{4, 6}};
  o.region_frame = "payload";
  o.region = Eigen::AlignedBox3d(Eigen::Vector3d(0.3, -0.6, 0.75), Eigen::Vector3d(0.9, 0.6, 1.1));
  return o;
}

TEST(GoalSampler, SameSeedSameGoalsOtherSeedOthers) {
  const Scene scene = load_scene(kSceneDir + "iiwa_desk.yaml");
  GoalSampler a(scene.problem, iiwa_options(3)), b(scene.problem, iiwa_options(3)),
      c(scene.problem, iiwa_options(4));
  const std::vector<Eigen::VectorXd> ga = a.sample(5), gb = b.sample(5), gc = c.sample(5);
  ASSERT_EQ(ga.size(), 5u);
  ASSERT_EQ(gc.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(ga[i], gb[i]);
    EXPECT_GT((ga[i] - gc[i]).norm(), 1e-3);
  }
  EXPECT_EQ(a.attempts(), b.attempts());
  EXPECT_GE(a.attempts(), 5);
}

TEST(GoalSampler, GoalsAreWithinLimitsRegionAndClear) {
  const Scene scene = load_scene(kSceneDir + "iiwa_desk.yaml");
  const Problem& p = scene.problem;
  const GoalSamplerOptions options = iiwa_options(11);
  GoalSampler sampler(p, options);
  const std::vector<Eigen::VectorXd> goals = sampler.sample(10);
  ASSERT_EQ(goals.size(), 10u);
  collision::CollisionWorld world(*p.model);
  for (const collision::Obstacle& o : p.obstacles) ASSERT_TRUE(world.add_obstacle(o).ok);
  collision::CollisionWorldOptions self;
  self.self_collision = true;
  self.self_collision_excluded = {{4, 6}};
  collision::CollisionWorld self_world(*p.model, self);
  dynamics::Data data(*p.model);
  const int payload = p.model->frame_index("payload");
  for (const Eigen::VectorXd& q : goals) {
    for (int j = 0; j < 7; ++j) {
      EXPECT_GE(q[j], p.model->bodies[j].limits.lower + options.limit_margin);
      EXPECT_LE(q[j], p.model->bodies[j].limits.upper - options.limit_margin);
    }
    dynamics::forward_kinematics(*p.model, data, q);
    const Eigen::Vector3d block = dynamics::frame_pose(*p.model, data, payload).translation();
    EXPECT_TRUE(options.region.contains(block)) << block.transpose();
    EXPECT_GE(world.closest(data, p.horizon).distance, p.objectives.collision_epsilon);
    EXPECT_GE(self_world.closest(data).distance, 0.0);
    EXPECT_TRUE(sampler.accepts(q));
  }
}

TEST(GoalSampler, RejectsCollisionsAndLimitMargins) {
  const Scene scene = load_scene(kSceneDir + "rr_reach.yaml");
  GoalSamplerOptions options;
  options.limit_margin = 0.1;
  GoalSampler sampler(scene.problem, options);
  // Upright: the forearm goes through the ball above the shoulder.
  EXPECT_FALSE(sampler.accepts(Eigen::Vector2d(0, 0)));
  EXPECT_TRUE(sampler.accepts(scene.problem.start_q));
  // Within the URDF limits (±π) but inside the margin.
  EXPECT_FALSE(sampler.accepts(Eigen::Vector2d(M_PI - 0.05, 0.5)));
  EXPECT_FALSE(sampler.accepts(Eigen::Vector3d(0.5, 0.5, 0)));  // wrong size
  for (const Eigen::VectorXd& q : sampler.sample(20)) {
    EXPECT_LE(q.cwiseAbs().maxCoeff(), M_PI - 0.1);
  }
}

TEST(GoalSampler, GivesUpOnAnEmptyRegion) {
  const Scene scene = load_scene(kSceneDir + "rr_reach.yaml");
  GoalSamplerOptions options;
  options.region_frame = "ee";
  options.region = Eigen::AlignedBox3d(Eigen::Vector3d(5, 5, 5), Eigen::Vector3d(6, 6, 6));
  options.max_attempts = 500;
  GoalSampler sampler(scene.problem, options);
  EXPECT_FALSE(sampler.sample().has_value());
  EXPECT_EQ(sampler.attempts(), 500);
  EXPECT_TRUE(sampler.sample(3).empty());
  options.region_frame = "no_such_frame";
  EXPECT_THROW(GoalSampler(scene.problem, options), std::invalid_argument);
}

}  // namespace
}  // namespace kinograph::planning

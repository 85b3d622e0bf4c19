// The hot paths promise no heap allocation after warm-up: query, closest, distance_gradient
// and SegmentChecker::check. Counted by replacing the global operator new in this binary.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <string>

#include "kinograph/collision/collision_world.h"
#include "kinograph/collision/distance_gradient.h"
#include "kinograph/collision/segment_checker.h"
#include "kinograph/dynamics/kinematics.h"

namespace {
std::atomic<long> g_allocations{0};
}

void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace kinograph::collision {
namespace {

TEST(CollisionAllocation, QueriesGradientsAndSegmentsAllocateNothingAfterWarmUp) {
  const dynamics::Model model = dynamics::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) +
                                                                "/robots/iiwa14/iiwa14.urdf");
  dynamics::Data data(model);
  CollisionWorldOptions opts;
  opts.self_collision = true;
  CollisionWorld world(model, opts);
  Obstacle desk;
  desk.id = 1;
  desk.shape = Shape::box(0.8, 1.2, 0.05);
  desk.pose.translation() = Eigen::Vector3d(0.5, 0, 0.5);
  ASSERT_TRUE(world.add_obstacle(desk));
  Obstacle ball;
  ball.id = 2;
  ball.shape = Shape::sphere(0.1);
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity(), b = a;
  a.translation() = Eigen::Vector3d(0.3, 0.3, 0.8);
  b.translation() = Eigen::Vector3d(-0.3, 0.3, 0.8);
  ball.trajectory = PoseTrajectory({0.0, 1.0}, {a, b});
  ASSERT_TRUE(world.add_obstacle(ball));
  DistanceGradientWorkspace ws(model);
  SegmentChecker checker(model);
  Eigen::VectorXd grad(model.nq()), q0(model.nq()), q1(model.nq());
  q0 << 0.3, 0.8, 0.1, -1.2, 0.2, 0.9, 0.0;
  q1 << -0.4, 1.0, 0.3, -0.8, -0.2, 0.5, 0.4;

  auto work = [&](double t) {
    int pairs = 0;
    dynamics::forward_kinematics(model, data, q0);
    for (const Proximity& p : world.query(data, t)) {
      distance_gradient(model, data, p, ws, grad);
      ++pairs;
    }
    world.closest(data, t);
    checker.check(world, data, q0, q1, t, t + 0.1);
    return pairs;
  };
  work(0.0);  // warm-up
  const long before = g_allocations.load();
  int pairs = 0;
  for (int i = 0; i < 10; ++i) pairs += work(0.1 * i);
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_GT(pairs, 0);  // the work did touch some pairs
}

}  // namespace
}  // namespace kinograph::collision

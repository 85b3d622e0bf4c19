// Where a replan joins the motion: only while an executor's recent commands follow one of this
// daemon's plans; at the latest state's time plus the latency, never before the last take-over;
// the plan's interpolant there, or its last knot once it has ended.
#include "daemon/motion_join.h"

#include <gtest/gtest.h>

#include "kinograph/execution/stopping_trajectory.h"
#include "kinograph/planning/io/scene.h"

namespace kinograph::daemon {
namespace {

class MotionJoinTest : public ::testing::Test {
 protected:
  MotionJoinTest() {
    const Eigen::VectorXd a = Eigen::VectorXd::Constant(7, 0.5), zero = Eigen::VectorXd::Zero(7);
    plan_ = execution::linear_acceleration_plan(model(), scene_.problem.start_q, zero,
                                                {0, 0.25, 0.75, 1.0}, {zero, a, -a, zero}, 5);
  }
  const dynamics::Model& model() const { return *scene_.problem.model; }

  planning::Scene scene_ =
      planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml");
  planning::Plan plan_;
};

TEST_F(MotionJoinTest, JoinsOnlyAnExecutorFollowingItsPlans) {
  MotionJoin join(model(), 0.3);
  EXPECT_FALSE(join.join(1'000'000, 0.5).has_value());  // no plan
  join.published({5, 1'000'000, 1'000'000, 1'000'000, plan_});
  EXPECT_FALSE(join.join(1'100'000, 0.5).has_value());  // no executor
  join.commanded(4, 1'100'000);                         // not one of ours
  EXPECT_FALSE(join.join(1'100'000, 0.5).has_value());
  join.commanded(-1, 1'100'000);  // a stop
  EXPECT_FALSE(join.join(1'100'000, 0.5).has_value());
  join.commanded(5, 1'100'000);
  EXPECT_TRUE(join.join(1'100'000, 0.5).has_value());
  EXPECT_FALSE(join.join(1'700'000, 0.5).has_value());  // the commands stopped 0.6 s ago
}

TEST_F(MotionJoinTest, JoinsThePlanAtTheLatencyAfterTheState) {
  MotionJoin join(model(), 0.3);
  join.published({5, 1'000'000, 1'000'000, 1'000'000, plan_});
  join.commanded(5, 1'100'000);
  const auto point = join.join(1'150'000, 0.5);
  ASSERT_TRUE(point.has_value());
  EXPECT_EQ(point->takeover_utime, 1'450'000);
  EXPECT_EQ(point->from_plan, 5);
  planning::TrajectorySampler sampler(model(), plan_);
  const planning::InterpolantPoint p = sampler.at(0.45);
  EXPECT_LE((point->q - p.q).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LE((point->qd - p.qd).cwiseAbs().maxCoeff(), 1e-15);
  // Past the plan's end: its last knot, at rest.
  const auto late = join.join(3'000'000, 0.5 + 2.0);
  ASSERT_TRUE(late.has_value());
  EXPECT_EQ(late->q, plan_.q.bottomRows(1).transpose());
}

TEST_F(MotionJoinTest, NeverTakesOverBeforeThePlanInForce) {
  MotionJoin join(model(), 0.0);
  join.published({5, 1'000'000, 1'400'000, 1'000'000, plan_});
  join.commanded(5, 1'100'000);
  const auto point = join.join(1'100'000, 0.5);
  ASSERT_TRUE(point.has_value());
  EXPECT_EQ(point->takeover_utime, 1'400'001);
}

}  // namespace
}  // namespace kinograph::daemon

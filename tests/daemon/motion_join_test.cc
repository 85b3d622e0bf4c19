// Where a replan joins the motion: only while an executor's recent commands follow one of this
// daemon's plans; at the latest state's time plus the latency, never before the last take-over;
// the plan's interpolant there, or its last knot once it has ended. And where a robot without
// states is along its daemon's published plans (PlannedMotion): nowhere before the first, the
// newest plan started by then (q and q̇), its last knot once it ended, an older plan until a
// newer one, waiting, starts; that motion continued as a warm start.
#include "daemon/motion_join.h"
#include "daemon/planned_motion.h"

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

TEST_F(MotionJoinTest, PlannedMotionIsWhereTheNewestStartedPlanHasTheRobot) {
  PlannedMotion motion(model());
  EXPECT_FALSE(motion.moving());
  EXPECT_FALSE(motion.at(1'000'000).has_value());
  motion.published({1, 1'000'000, 1'000'000, -1, plan_});
  ASSERT_TRUE(motion.moving());
  // Mid-motion: the interpolant's q and q̇, not the plan's start.
  const auto mid = motion.at(1'400'000);
  ASSERT_TRUE(mid.has_value());
  planning::TrajectorySampler sampler(model(), plan_);
  const planning::InterpolantPoint p = sampler.at(0.4);
  EXPECT_LE((mid->q - p.q).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LE((mid->qd - p.qd).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_GT((mid->q - scene_.problem.start_q).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_GT(mid->qd.cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_EQ(mid->plan_id, 1);
  // Once it ended: its last knot.
  EXPECT_EQ(motion.at(5'000'000)->q, plan_.q.bottomRows(1).transpose());
  // Before it started: its first knot.
  EXPECT_EQ(motion.at(0)->q, plan_.q.topRows(1).transpose());
}

TEST_F(MotionJoinTest, PlannedMotionAnOlderPlanIsInForceUntilANewerOneStarts) {
  PlannedMotion motion(model());
  motion.published({1, 1'000'000, 1'000'000, -1, plan_});
  planning::Plan later = plan_;
  later.q.array() += 0.1;
  motion.published({2, 3'000'000, 3'000'000, -1, later});  // waits until 3 s
  EXPECT_EQ(motion.at(1'400'000)->plan_id, 1);
  EXPECT_EQ(motion.at(2'900'000)->q, plan_.q.bottomRows(1).transpose());
  EXPECT_EQ(motion.at(3'000'000)->plan_id, 2);
  // A newer plan that starts earlier replaces the waiting one from its own start on.
  motion.published({3, 2'000'000, 2'000'000, -1, plan_});
  EXPECT_EQ(motion.at(1'400'000)->plan_id, 1);
  EXPECT_EQ(motion.at(3'500'000)->plan_id, 3);
}

TEST_F(MotionJoinTest, PlannedMotionAheadIsThatMotionContinuedAtAPlansKnots) {
  PlannedMotion motion(model());
  EXPECT_FALSE(motion.ahead(1'000'000, 1.0, 4).has_value());
  motion.published({1, 1'000'000, 1'000'000, -1, plan_});
  const std::optional<planning::Plan> ahead = motion.ahead(1'500'000, 1.0, 4);  // 0.5 s in
  ASSERT_TRUE(ahead.has_value());
  ASSERT_EQ(ahead->q.rows(), 5);
  EXPECT_EQ(ahead->t, (std::vector<double>{0, 0.25, 0.5, 0.75, 1.0}));
  planning::TrajectorySampler sampler(model(), plan_);
  const planning::InterpolantPoint p = sampler.at(0.75);  // knot 1: 0.25 s later
  EXPECT_LE((ahead->q.row(1).transpose() - p.q).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LE((ahead->qd.row(1).transpose() - p.qd).cwiseAbs().maxCoeff(), 1e-15);
  // Past the plan's end (1 s long): held at its last knot.
  EXPECT_EQ(ahead->q.row(4), plan_.q.bottomRows(1));
}

}  // namespace
}  // namespace kinograph::daemon

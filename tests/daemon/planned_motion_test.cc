// Where a robot without states is along its daemon's published plans: nowhere before the first,
// the newest plan started by then (its interpolant, q and q̇), its last knot once it ended, and
// an older plan until a newer one, waiting, starts.
#include "daemon/planned_motion.h"

#include <gtest/gtest.h>

#include "kinograph/execution/stopping_trajectory.h"
#include "kinograph/planning/io/scene.h"

namespace kinograph::daemon {
namespace {

class PlannedMotionTest : public ::testing::Test {
 protected:
  PlannedMotionTest() {
    const Eigen::VectorXd a = Eigen::VectorXd::Constant(7, 0.5), zero = Eigen::VectorXd::Zero(7);
    plan_ = execution::linear_acceleration_plan(model(), scene_.problem.start_q, zero,
                                                {0, 0.25, 0.75, 1.0}, {zero, a, -a, zero}, 5);
  }
  const dynamics::Model& model() const { return *scene_.problem.model; }
  // plan_ read at plan time t.
  planning::InterpolantPoint plan_at(double t) {
    planning::TrajectorySampler sampler(model(), plan_);
    return sampler.at(t);
  }

  planning::Scene scene_ =
      planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml");
  planning::Plan plan_;
};

TEST_F(PlannedMotionTest, IsWhereTheNewestStartedPlanHasTheRobot) {
  PlannedMotion motion(model());
  EXPECT_FALSE(motion.moving());
  EXPECT_FALSE(motion.at(1'000'000).has_value());
  motion.published({1, 1'000'000, 1'000'000, -1, plan_});
  ASSERT_TRUE(motion.moving());
  // Mid-motion: the interpolant's q and q̇, not the plan's start.
  const auto mid = motion.at(1'400'000);
  ASSERT_TRUE(mid.has_value());
  const planning::InterpolantPoint p = plan_at(0.4);
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

TEST_F(PlannedMotionTest, AnOlderPlanIsInForceUntilANewerOneStarts) {
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

}  // namespace
}  // namespace kinograph::daemon

// Plans on the robot's clock: a plan is in force from its take-over time, read through the one
// interpolant (the same numbers as TrajectorySampler), its last knot held after it ends; a
// replan that starts where the plan in force is at the take-over joins it without a jump, and
// one that does not shows its jump.
#include "kinograph/execution/plan_schedule.h"

#include <gtest/gtest.h>

#include <cmath>

#include "kinograph/execution/stopping_trajectory.h"
#include "kinograph/planning/io/scene.h"

namespace kinograph::execution {
namespace {

class PlanScheduleTest : public ::testing::Test {
 protected:
  // A 1 s motion from `q0` at `qd0` whose acceleration goes linearly from a to −a and back.
  planning::Plan motion(const Eigen::VectorXd& q0, const Eigen::VectorXd& qd0, double a) {
    const Eigen::VectorXd acc = Eigen::VectorXd::Constant(n(), a);
    return linear_acceleration_plan(model(), q0, qd0, {0, 0.5, 1.0}, {acc, -acc, acc}, 5);
  }
  const dynamics::Model& model() const { return *scene_.problem.model; }
  int n() const { return model().nq(); }

  planning::Scene scene_ =
      planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml");
};

TEST_F(PlanScheduleTest, NothingBeforeTheFirstTakeOver) {
  PlanSchedule schedule(model());
  EXPECT_FALSE(schedule.at(0).has_value());
  schedule.add({7, 1'000'000, 1'200'000, 900'000,
                motion(scene_.problem.start_q, Eigen::VectorXd::Zero(n()), 0.5)});
  EXPECT_FALSE(schedule.at(1'199'999).has_value());
  const auto s = schedule.at(1'200'000);
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->plan_id, 7);
  EXPECT_EQ(s->utime, 1'200'000);
  ASSERT_EQ(schedule.takeovers().size(), 1u);
  EXPECT_EQ(schedule.takeovers()[0].from, -1);
  EXPECT_EQ(schedule.takeovers()[0].to, 7);
}

TEST_F(PlanScheduleTest, ReadsThePlanThroughTheSampler) {
  const planning::Plan plan = motion(scene_.problem.start_q, Eigen::VectorXd::Zero(n()), 0.5);
  planning::TrajectorySampler sampler(model(), plan);
  PlanSchedule schedule(model());
  schedule.add({1, 2'000'000, 2'000'000, -1, plan});
  for (const int64_t dt_us : {0, 37'000, 250'000, 500'000, 777'777, 999'999}) {
    const auto s = schedule.at(2'000'000 + dt_us);
    ASSERT_TRUE(s.has_value());
    const planning::InterpolantPoint p = sampler.at(dt_us * 1e-6);
    EXPECT_EQ((s->q - p.q).cwiseAbs().maxCoeff(), 0.0) << dt_us;
    EXPECT_EQ((s->qd - p.qd).cwiseAbs().maxCoeff(), 0.0) << dt_us;
    EXPECT_EQ((s->tau - p.tau).cwiseAbs().maxCoeff(), 0.0) << dt_us;
  }
}

TEST_F(PlanScheduleTest, HoldsTheLastKnotAfterTheEnd) {
  // A rest-to-rest stop: its last knot is at rest.
  const Eigen::VectorXd qd0 = Eigen::VectorXd::Constant(n(), 0.2);
  StoppingTrajectory stop =
      stopping_trajectory(scene_.problem, scene_.problem.start_q, qd0, Eigen::VectorXd::Zero(n()));
  ASSERT_TRUE(stop.valid) << stop.reason;
  const planning::Plan& plan = stop.plan;
  PlanSchedule schedule(model());
  schedule.add({3, 0, 0, -1, plan});
  const Eigen::Index last = plan.q.rows() - 1;
  for (const int64_t t :
       {static_cast<int64_t>(std::llround(plan.t.back() * 1e6)) + 1, int64_t{60'000'000}}) {
    const auto s = schedule.at(t);
    ASSERT_TRUE(s.has_value());
    EXPECT_EQ(s->q, plan.q.row(last).transpose());
    EXPECT_LE(s->qd.cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_EQ(s->tau, plan.tau.row(last).transpose());
  }
}

TEST_F(PlanScheduleTest, AReplanFromTheTakeOverStateJoinsWithoutAJump) {
  const planning::Plan first = motion(scene_.problem.start_q, Eigen::VectorXd::Zero(n()), 0.5);
  planning::TrajectorySampler sampler(model(), first);
  // The replan starts where the first plan is 0.3137 s in (between knots).
  const planning::InterpolantPoint join = sampler.at(0.3137);
  const planning::Plan second = motion(join.q, join.qd, -0.3);
  PlanSchedule schedule(model());
  schedule.add({1, 10'000'000, 10'000'000, -1, first});
  ASSERT_TRUE(schedule.at(10'100'000).has_value());
  schedule.add({2, 10'313'700, 10'313'700, 10'200'000, second});
  EXPECT_EQ(schedule.at(10'313'699)->plan_id, 1);
  const auto s = schedule.at(10'313'700);
  EXPECT_EQ(s->plan_id, 2);
  ASSERT_EQ(schedule.takeovers().size(), 2u);
  const Takeover& t = schedule.takeovers()[1];
  EXPECT_EQ(t.from, 1);
  EXPECT_EQ(t.to, 2);
  EXPECT_LE(t.jump_q, 1e-12);
  EXPECT_LE(t.jump_qd, 1e-12);
}

TEST_F(PlanScheduleTest, AReplanFromElsewhereShowsItsJump) {
  const planning::Plan first = motion(scene_.problem.start_q, Eigen::VectorXd::Zero(n()), 0.5);
  Eigen::VectorXd q = scene_.problem.start_q;
  q[2] += 0.01;
  PlanSchedule schedule(model());
  schedule.add({1, 0, 0, -1, first});
  schedule.add({2, 0, 0, -1, motion(q, Eigen::VectorXd::Zero(n()), 0.5)});  // replaces 1 queued
  schedule.at(0);
  ASSERT_EQ(schedule.takeovers().size(), 1u);
  EXPECT_EQ(schedule.takeovers()[0].to, 2);  // plan 1 never took over
  // Plan 4 starts 0.01 rad away on joint 3, where plan 2 has barely moved 2 µs in.
  schedule.add({4, 0, 2, -1, first});
  schedule.at(2);
  ASSERT_EQ(schedule.takeovers().size(), 2u);
  EXPECT_NEAR(schedule.takeovers()[1].jump_q, 0.01, 1e-9);
}

TEST_F(PlanScheduleTest, ANewerPlanDropsQueuedPlansThatWouldTakeOverLater) {
  const planning::Plan plan = motion(scene_.problem.start_q, Eigen::VectorXd::Zero(n()), 0.5);
  PlanSchedule schedule(model());
  schedule.add({1, 0, 0, -1, plan});
  schedule.add({2, 0, 500, -1, plan});
  schedule.add({3, 0, 400, -1, plan});  // newer, earlier: plan 2 is dropped
  EXPECT_EQ(schedule.at(450)->plan_id, 3);
  EXPECT_EQ(schedule.at(10'000)->plan_id, 3);
  schedule.clear();
  EXPECT_FALSE(schedule.at(20'000).has_value());
}

TEST_F(PlanScheduleTest, RefusesAPlanItCannotSample) {
  planning::Plan plan = motion(scene_.problem.start_q, Eigen::VectorXd::Zero(n()), 0.5);
  plan.q.conservativeResize(Eigen::NoChange, 6);
  PlanSchedule schedule(model());
  EXPECT_THROW(schedule.add({1, 0, 0, -1, plan}), std::invalid_argument);
}

}  // namespace
}  // namespace kinograph::execution

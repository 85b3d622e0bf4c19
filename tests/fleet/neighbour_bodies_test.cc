// A neighbour's bodies as obstacles: posed by forward kinematics at a state, along a plan on the
// own clock (the plan's time shifted by the clock offset), held at the first knot before and the
// last knot after the plan, and named after the neighbour and the link.
#include "kinograph/fleet/neighbour_bodies.h"

#include <gtest/gtest.h>

#include <random>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/trajectory_sampler.h"
#include "tests/fleet/slider.h"

namespace kinograph::fleet {
namespace {

using testing::constant_velocity;
using testing::slider;

class NeighbourBodiesTest : public ::testing::Test {
 protected:
  // The iiwa of the desk scene (payload attached).
  Neighbour iiwa() const { return {"right", scene_.problem.model}; }
  // A 1 s plan of the iiwa moving every joint from q0 at constant velocity v (20 intervals).
  planning::Plan iiwa_plan(const Eigen::VectorXd& q0, const Eigen::VectorXd& v) const {
    planning::Plan p;
    const int n = static_cast<int>(q0.size()), knots = 20;
    p.q.resize(knots + 1, n);
    p.qd.resize(knots + 1, n);
    p.qdd = Eigen::MatrixXd::Zero(knots + 1, n);
    p.tau = Eigen::MatrixXd::Zero(knots + 1, n);
    for (int k = 0; k <= knots; ++k) {
      p.t.push_back(static_cast<double>(k) / knots);
      p.q.row(k) = (q0 + v * p.t.back()).transpose();
      p.qd.row(k) = v.transpose();
    }
    return p;
  }

  planning::Scene scene_ =
      planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml");
};

void expect_pose_near(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double tol = 1e-9) {
  EXPECT_LT((a.translation() - b.translation()).norm(), tol);
  EXPECT_LT((a.linear() - b.linear()).norm(), tol);
}

TEST_F(NeighbourBodiesTest, StaticBodiesAreTheGeometryPosedByForwardKinematics) {
  const Neighbour n = iiwa();
  const dynamics::Model& model = *n.model;
  Eigen::VectorXd q(7);
  q << 0.3, -0.5, 0.2, -1.1, 0.4, 0.7, -0.2;
  const std::vector<NeighbourBody> bodies = bodies_at(n, q, 100);
  ASSERT_EQ(bodies.size(), model.collision.size());
  dynamics::Data data(model);
  dynamics::forward_kinematics(model, data, q);
  for (size_t g = 0; g < bodies.size(); ++g) {
    const dynamics::Geometry& geom = model.collision[g];
    EXPECT_EQ(bodies[g].obstacle.id, 100 + static_cast<int>(g));
    EXPECT_FALSE(bodies[g].obstacle.is_moving());
    EXPECT_EQ(bodies[g].name, "neighbour 'right' link '" + geom.link_name + "'");
    const Eigen::Isometry3d expected =
        geom.body < 0 ? geom.origin : data.body_pose[geom.body] * geom.origin;
    expect_pose_near(bodies[g].obstacle.pose, expected);
  }
}

TEST_F(NeighbourBodiesTest, MovingBodiesFollowThePlanOnTheOwnClock) {
  const Neighbour n = iiwa();
  const dynamics::Model& model = *n.model;
  Eigen::VectorXd q0(7), v(7);
  q0 << 0.3, -0.5, 0.2, -1.1, 0.4, 0.7, -0.2;
  v << 0.4, 0.3, -0.2, 0.5, -0.6, 0.2, 0.1;
  const planning::Plan plan = iiwa_plan(q0, v);
  const double offset = 2.5;  // the neighbour's plan starts 2.5 s after the own clock origin
  const std::vector<NeighbourBody> bodies = bodies_along(n, plan, offset);
  planning::TrajectorySampler sampler(model, plan);
  dynamics::Data data(model);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> within(0.0, 1.0);
  // Inside the plan at random times (between the samples too), before it and after it.
  std::vector<std::pair<double, Eigen::VectorXd>> checks;
  for (int i = 0; i < 20; ++i) {
    const double tau = within(rng);
    checks.emplace_back(offset + tau, sampler.at(tau).q);
  }
  checks.emplace_back(offset - 1.0, q0);
  checks.emplace_back(offset + 3.0, Eigen::VectorXd(plan.q.row(plan.q.rows() - 1).transpose()));
  for (const auto& [t, q] : checks) {
    dynamics::forward_kinematics(model, data, q);
    for (size_t g = 0; g < bodies.size(); ++g) {
      const dynamics::Geometry& geom = model.collision[g];
      EXPECT_EQ(bodies[g].obstacle.is_moving(), geom.body >= 0) << geom.link_name;
      const Eigen::Isometry3d expected =
          geom.body < 0 ? geom.origin : data.body_pose[geom.body] * geom.origin;
      // Poses between samples are interpolated; a 1/200 s step at these speeds moves a link by
      // well under a millimetre.
      expect_pose_near(bodies[g].obstacle.pose_at(t), expected, 2e-3);
    }
  }
}

TEST_F(NeighbourBodiesTest, SamplesAreExactAtTheSweepTimes) {
  const auto model = slider(Eigen::Vector3d(0, 1, 0));
  const planning::Plan plan = constant_velocity(0.5, -0.4, 2.0, 4);
  const std::vector<double> times = sweep_times(plan, 1.0, 10);
  ASSERT_EQ(times.size(), 41u);
  EXPECT_DOUBLE_EQ(times.front(), 1.0);
  EXPECT_DOUBLE_EQ(times.back(), 3.0);
  const std::vector<NeighbourBody> bodies = bodies_along({"left", model}, plan, 1.0);
  ASSERT_EQ(bodies.size(), 1u);
  EXPECT_EQ(bodies[0].name, "neighbour 'left' link 'ball'");
  for (const double t : times) {
    const Eigen::Vector3d at = bodies[0].obstacle.pose_at(t).translation();
    EXPECT_NEAR(at.x(), 0.5 - 0.4 * (t - 1.0), 1e-12);
    EXPECT_NEAR(at.y(), 1.0, 1e-12);
  }
}

TEST(ClockOffset, IsTheDifferenceOfTheUtimesInSeconds) {
  EXPECT_DOUBLE_EQ(clock_offset(3'500'000, 1'000'000), 2.5);
  EXPECT_DOUBLE_EQ(clock_offset(1'000'000, 3'500'000), -2.5);
}

TEST_F(NeighbourBodiesTest, BadStateAndPlanNameTheNeighbour) {
  const Neighbour n = iiwa();
  try {
    bodies_at(n, Eigen::VectorXd::Zero(3));
    FAIL() << "a 3-joint state for the iiwa was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("neighbour 'right'"), std::string::npos) << e.what();
  }
  Eigen::VectorXd nan = Eigen::VectorXd::Zero(7);
  nan[2] = std::nan("");
  EXPECT_THROW(bodies_at(n, nan), std::invalid_argument);
  planning::Plan one_knot = iiwa_plan(Eigen::VectorXd::Zero(7), Eigen::VectorXd::Zero(7));
  one_knot.t.resize(1);
  try {
    bodies_along(n, one_knot, 0.0);
    FAIL() << "a plan with one time was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("neighbour 'right'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(sweep_times(one_knot, 0.0, 0), std::invalid_argument);
}

}  // namespace
}  // namespace kinograph::fleet

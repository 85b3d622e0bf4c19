// End-to-end batch plans: Acrobot swing-up, RR reach past an obstacle, iiwa carrying the block
// past a desk, and impossible problems that must fail cleanly.
#include "kinograph/planning/batch_planner.h"

#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <limits>

#include "kinograph/dynamics/kinematics.h"
#include "kinograph/dynamics/payload.h"

namespace kinograph::planning {
namespace {

std::shared_ptr<const dynamics::Model> load(const std::string& rel) {
  return std::make_shared<const dynamics::Model>(
      dynamics::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) + "/" + rel));
}

Problem acrobot_swingup() {
  Problem p;
  p.name = "acrobot_swingup";
  p.model = load("robots/acrobot/acrobot.urdf");
  p.horizon = 10;
  p.steps = 100;
  p.start_q = Eigen::Vector2d(0, 0);
  p.start_qd = Eigen::Vector2d(0, 0);
  p.goal.q = Eigen::Vector2d(M_PI, 0);
  return p;
}

TEST(BatchPlanner, AcrobotSwingUpValidates) {
  if (std::getenv("KINOGRAPH_DEBUG")) spdlog::set_level(spdlog::level::debug);
  const Problem p = acrobot_swingup();
  const Plan plan = BatchPlanner().plan(p);
  const Validation& v = plan.validation;
  for (const auto& f : v.failures) ADD_FAILURE() << f;
  EXPECT_EQ(plan.stats.status, "converged") << plan.stats.reason;
  EXPECT_TRUE(plan.success());
  EXPECT_LT(v.max_unactuated_torque, 1e-3);
  EXPECT_LE(plan.tau.col(1).cwiseAbs().maxCoeff(), 8.0 + 1e-3);
  EXPECT_NEAR(plan.q(p.steps, 0), M_PI, 1e-6);
  RecordProperty("iterations", plan.stats.iterations);
  std::printf(
      "acrobot: %s its=%d outer=%d solves=%d time=%.3f s cost=%.4g viol=%.3g "
      "pos=%.3g vel=%.3g unact=%.3g maxtau=%.3f\n",
      plan.stats.status.c_str(), plan.stats.iterations, plan.stats.outer_iterations,
      plan.stats.linear_solves, plan.stats.solve_time_s, plan.stats.cost,
      plan.stats.max_constraint_violation, v.max_position_consistency, v.max_velocity_consistency,
      v.max_unactuated_torque, plan.tau.col(1).cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace kinograph::planning

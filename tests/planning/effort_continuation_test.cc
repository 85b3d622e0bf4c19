// Continuation in the effort limits: which problems it applies to and the scaled problems it
// solves on the way.
#include "kinograph/planning/batch/effort_continuation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "tests/planning/test_problems.h"

namespace kinograph::planning {
namespace {

TEST(EffortContinuation, AppliesToAnUnactuatedJointWithALimitedActuatedOne) {
  EXPECT_TRUE(effort_continuation_applies(testing::acrobot_swingup()));
  EXPECT_FALSE(effort_continuation_applies(testing::rr_reach()));  // fully actuated
  Problem unlimited = testing::acrobot_swingup();
  auto model = std::make_shared<dynamics::Model>(*unlimited.model);
  model->bodies[1].limits.effort = std::numeric_limits<double>::infinity();
  unlimited.model = model;
  EXPECT_FALSE(effort_continuation_applies(unlimited));  // nothing to narrow
}

TEST(EffortContinuation, ScalesOnlyTheActuatedJointsFiniteLimits) {
  const Problem p = testing::acrobot_swingup();
  const Problem s = with_effort_scaled(p, 1.5);
  EXPECT_DOUBLE_EQ(s.model->bodies[1].limits.effort, 1.5 * p.model->bodies[1].limits.effort);
  EXPECT_EQ(s.model->bodies[0].limits.effort, p.model->bodies[0].limits.effort);  // unactuated
  EXPECT_DOUBLE_EQ(s.model->bodies[1].limits.velocity, p.model->bodies[1].limits.velocity);
  EXPECT_DOUBLE_EQ(p.model->bodies[1].limits.effort, 8.0);  // the original is left as it was
  EXPECT_THROW(with_effort_scaled(p, 0), std::invalid_argument);
  EXPECT_THROW(with_effort_scaled(p, std::nan("")), std::invalid_argument);
}

}  // namespace
}  // namespace kinograph::planning

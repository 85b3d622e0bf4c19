// End-to-end batch plans: Acrobot swing-up, RR reach past an obstacle, iiwa carrying the block
// past a desk, and impossible problems that must fail cleanly.
#include "kinograph/planning/batch/batch_planner.h"

#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "kinograph/dynamics/kinematics.h"
#include "kinograph/dynamics/payload.h"
#include "kinograph/planning/io/scene.h"
#include "test_problems.h"

namespace kinograph::planning {
namespace {

std::shared_ptr<const dynamics::Model> load(const std::string& rel) {
  return std::make_shared<const dynamics::Model>(
      dynamics::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) + "/" + rel));
}

Problem acrobot_swingup() {
  Problem p;
  p.name = "acrobot_swingup";
  p.model = testing::acrobot_model();
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
  EXPECT_EQ(plan.stats.status, PlanStatus::kConverged) << plan.stats.reason;
  EXPECT_TRUE(plan.success());
  EXPECT_LT(v.max_unactuated_torque, 1e-3);
  EXPECT_LE(plan.tau.col(1).cwiseAbs().maxCoeff(), 8.0 + 1e-3);
  EXPECT_NEAR(plan.q(p.steps, 0), M_PI, 1e-6);
  RecordProperty("iterations", plan.stats.iterations);
  std::printf(
      "acrobot: %s its=%d outer=%d solves=%d time=%.3f s cost=%.4g viol=%.3g "
      "pos=%.3g vel=%.3g unact=%.3g maxtau=%.3f\n",
      to_string(plan.stats.status).c_str(), plan.stats.iterations, plan.stats.outer_iterations,
      plan.stats.linear_solves, plan.stats.solve_time_s, plan.stats.cost,
      plan.stats.max_constraint_violation, v.max_position_consistency, v.max_velocity_consistency,
      v.max_unactuated_torque, plan.tau.col(1).cwiseAbs().maxCoeff());
}

// The warm-up solve in longer RK4 steps changes the path to the plan, not what it must meet:
// with and without it the swing-up validates on the interpolant, at nearly the same cost.
TEST(BatchPlanner, AcrobotWarmUpSolveKeepsThePlanValid) {
  const Problem p = acrobot_swingup();
  BatchPlannerOptions without;
  without.warmup_integration_step = 0;
  const Plan a = BatchPlanner().plan(p), b = BatchPlanner(without).plan(p);
  for (const Plan* plan : {&a, &b}) {
    for (const auto& f : plan->validation.failures) ADD_FAILURE() << f;
    EXPECT_TRUE(plan->success()) << plan->stats.reason;
    EXPECT_LT(plan->validation.max_unactuated_torque_between, 1e-3);
    EXPECT_LT(plan->validation.max_tau_violation_between, 0.08);  // 1 % of 8 N·m
  }
  EXPECT_NEAR(a.stats.cost, b.stats.cost, 0.05 * b.stats.cost);
}

// A grid four times finer than the scene's: the straight line does not plan it (the knot-only
// solve stalls), the refinement through 100 and 200 steps does, each refined solve a short
// projection.
TEST(BatchPlanner, AcrobotFineGridPlansByRefinement) {
  Problem p = acrobot_swingup();
  p.steps = 400;
  const Plan plan = BatchPlanner().plan(p);
  for (const auto& f : plan.validation.failures) ADD_FAILURE() << f;
  EXPECT_TRUE(plan.success()) << plan.stats.reason;
  EXPECT_EQ(plan.stats.status, PlanStatus::kConverged) << plan.stats.reason;
  EXPECT_EQ(plan.q.rows(), 401);
  EXPECT_EQ(plan.stats.attempts, 3);      // 100, 200 and 400 steps
  EXPECT_LT(plan.stats.iterations, 200);  // the 100-step plan's 111 and a few more
  EXPECT_LT(plan.validation.max_unactuated_torque_between, 1e-3);
  EXPECT_LT(plan.validation.max_tau_violation_between, 0.08);  // 1 % of 8 N·m
}

Problem rr_reach() {
  Problem p;
  p.name = "rr_reach";
  p.model = load("robots/rr/rr.urdf");
  p.horizon = 3;
  p.steps = 30;
  p.start_q = Eigen::Vector2d(-1.2, 0);
  p.start_qd = Eigen::Vector2d(0, 0);
  p.goal.q = Eigen::Vector2d(1.2, 0);
  // A ball the straight line's upright arm would hit with its tip: the arm must bend past it.
  collision::Obstacle ball;
  ball.id = 1;
  ball.shape = collision::Shape::sphere(0.12);
  ball.pose.translation() = Eigen::Vector3d(0.1, 0, 1.9);
  p.obstacles.push_back(ball);
  return p;
}

TEST(BatchPlanner, RrReachAvoidsTheBall) {
  const Problem p = rr_reach();
  const Plan plan = BatchPlanner().plan(p);
  for (const auto& f : plan.validation.failures) ADD_FAILURE() << f;
  EXPECT_TRUE(plan.success()) << plan.stats.reason;
  EXPECT_GE(plan.validation.min_clearance, 0.0);
  // The straight line would have collided: the elbow moved.
  EXPECT_GT(plan.q.col(1).cwiseAbs().maxCoeff(), 0.05);
  std::printf("rr: %s its=%d outer=%d time=%.3f s clearance=%.4f\n", to_string(plan.stats.status).c_str(),
              plan.stats.iterations, plan.stats.outer_iterations, plan.stats.solve_time_s,
              plan.validation.min_clearance);
}

std::shared_ptr<const dynamics::Model> iiwa_with_block() {
  return std::make_shared<const dynamics::Model>(dynamics::attach_box_payload(
      *load("robots/iiwa14/iiwa14.urdf"), "iiwa_link_ee_kuka", 2.0, {0.1, 0.1, 0.1},
      Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.05))));
}

Problem iiwa_desk() {
  Problem p;
  p.name = "iiwa_desk";
  p.model = iiwa_with_block();
  p.horizon = 2;
  p.steps = 40;
  Eigen::VectorXd qs(7), qg(7);
  qs << -0.9, 0.7, 0, -1.2, 0, 0.9, 0;
  qg << 0.9, 0.7, 0, -1.2, 0, 0.9, 0;
  p.start_q = qs;
  p.start_qd = Eigen::VectorXd::Zero(7);
  p.goal.q = qg;
  // A box where the straight line carries the block (joint 1 sweeps it through x > 0, y = 0).
  Eigen::VectorXd mid = 0.5 * (qs + qg);
  dynamics::Data d(*p.model);
  dynamics::forward_kinematics(*p.model, d, mid);
  const Eigen::Vector3d tip =
      dynamics::frame_pose(*p.model, d, p.model->frame_index("payload")).translation();
  collision::Obstacle desk;
  desk.id = 3;
  desk.shape = collision::Shape::box(0.3, 0.3, 0.3);
  desk.pose.translation() = tip + Eigen::Vector3d(0.1, 0, 0);
  p.obstacles.push_back(desk);
  return p;
}

TEST(BatchPlanner, IiwaCarriesTheBlockPastTheBox) {
  if (std::getenv("KINOGRAPH_DEBUG")) spdlog::set_level(spdlog::level::debug);
  const Problem p = iiwa_desk();
  const Plan plan = BatchPlanner().plan(p);
  for (const auto& f : plan.validation.failures) ADD_FAILURE() << f;
  EXPECT_TRUE(plan.success()) << plan.stats.reason;
  EXPECT_GE(plan.validation.min_clearance, 0.0);
  std::printf("iiwa: %s its=%d outer=%d time=%.3f s clearance=%.4f maxtau_excess=%.3g\n",
              to_string(plan.stats.status).c_str(), plan.stats.iterations, plan.stats.outer_iterations,
              plan.stats.solve_time_s, plan.validation.min_clearance,
              plan.validation.max_tau_violation);
}

// Every part of the time breakdown was measured within the plan call, so the parts are
// non-negative and sum to at most its wall time; the parts every plan runs are positive.
void expect_times_account_for(const Plan& plan) {
  const SolveTimes& t = plan.stats.times;
  for (double part :
       {t.initialization_s, t.graph_building_s, t.linearization_s, t.factorization_s,
        t.triangular_solve_s, t.multipliers_s, t.between_knot_checks_s, t.validation_s}) {
    EXPECT_GE(part, 0);
  }
  EXPECT_GT(t.graph_building_s, 0);
  EXPECT_GT(t.linearization_s, 0);
  EXPECT_GT(t.factorization_s, 0);
  EXPECT_GT(t.triangular_solve_s, 0);
  EXPECT_GT(t.validation_s, 0);
  EXPECT_LE(t.total_s(), plan.stats.solve_time_s);
}

TEST(BatchPlanner, TimesAccountForThePlan) {
  // The RR reach ranks detours around its ball (initialization); the Acrobot's solves check the
  // interpolant between the knots before its rows join the graph.
  const Plan rr = BatchPlanner().plan(rr_reach());
  ASSERT_TRUE(rr.success()) << rr.stats.reason;
  expect_times_account_for(rr);
  EXPECT_GT(rr.stats.times.initialization_s, 0);
  const Plan acrobot = BatchPlanner().plan(acrobot_swingup());
  ASSERT_TRUE(acrobot.success()) << acrobot.stats.reason;
  expect_times_account_for(acrobot);
  EXPECT_GT(acrobot.stats.times.between_knot_checks_s, 0);
}

TEST(BatchPlanner, LimitRowsTheSolveAlreadyKeepsAreNotReSolved) {
  // The desk task's knot-only solve comes within 10 % of a limit between some knots but keeps
  // every limit there: the rows added for those intervals change nothing, so the plan is the
  // knot-only solve's (as with no limit points between knots at all), on the graph with them.
  const Problem p =
      load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml").problem;
  BatchSolution with_rows;
  const Plan plan = BatchPlanner().plan(p, nullptr, &with_rows);
  ASSERT_TRUE(plan.success()) << plan.stats.reason;
  const auto interval_factors = std::count_if(
      with_rows.graph.entries.begin(), with_rows.graph.entries.end(),
      [](const FactorEntry& e) { return e.key.role == FactorRole::kInterval; });
  EXPECT_GT(interval_factors, 0);
  EXPECT_LE(worst_constraint(with_rows.graph.constraints(false), with_rows.graph.values)
                .scaled_violation,
            OuterLoopOptions().constraint_tolerance);
  // Every constraint of the solution's graph has its multipliers (the incremental planner
  // carries them into its tree).
  for (const FactorEntry* e : with_rows.graph.constraints(false)) {
    EXPECT_NO_THROW((void)with_rows.constraints.at(e->key)) << "step " << e->key.step;
  }
  Problem knots_only = p;
  knots_only.objectives.limit_substeps = 0;
  const Plan reference = BatchPlanner().plan(knots_only);
  ASSERT_TRUE(reference.success()) << reference.stats.reason;
  EXPECT_EQ(plan.stats.iterations, reference.stats.iterations);
  EXPECT_EQ(plan.q, reference.q);
  EXPECT_EQ(plan.qd, reference.qd);
}

TEST(BatchPlanner, ImpossibleProblemsFailCleanly) {
  BatchPlanner planner;
  {  // goal outside the joint limits
    Problem p = rr_reach();
    p.goal.q[0] = 4.0;
    const Plan plan = planner.plan(p);
    EXPECT_FALSE(plan.success());
    EXPECT_EQ(plan.stats.status, PlanStatus::kInvalidProblem);
    EXPECT_NE(plan.stats.reason.find("joint1"), std::string::npos) << plan.stats.reason;
  }
  {  // start in collision
    Problem p = rr_reach();
    p.start_q = Eigen::Vector2d(0, 0);
    const Plan plan = planner.plan(p);
    EXPECT_EQ(plan.stats.status, PlanStatus::kInvalidProblem);
    EXPECT_NE(plan.stats.reason.find("collision"), std::string::npos) << plan.stats.reason;
  }
  {  // NaN input
    Problem p = rr_reach();
    p.start_q[1] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(planner.plan(p).stats.status, PlanStatus::kInvalidProblem);
  }
  {  // elbow torque far too low to swing up: bounded iterations, "infeasible", never valid
    Problem p = acrobot_swingup();
    auto weak = std::make_shared<dynamics::Model>(*p.model);
    weak->bodies[1].limits.effort = 0.2;
    p.model = weak;
    BatchPlannerOptions o;
    o.outer_loop.max_total_iterations = 150;
    o.effort_continuation.clear();  // one solve: its iteration limit is what this checks
    const Plan plan = BatchPlanner(o).plan(p);
    EXPECT_FALSE(plan.success());
    EXPECT_EQ(plan.stats.status, PlanStatus::kInfeasible);
    EXPECT_LE(plan.stats.iterations, 150);
    EXPECT_FALSE(plan.stats.reason.empty());
  }
}

}  // namespace
}  // namespace kinograph::planning

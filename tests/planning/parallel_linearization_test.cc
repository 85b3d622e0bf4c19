// The planner's real graphs linearized on two threads give the same H, g and cost to the bit as
// on one: the factors marked Factor::parallel_safe (dynamics through the per-worker
// DynamicsWorkspace, pose, interval, DFG rows, and the collision hinges through a Bullet world
// per worker) really touch only their own state.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <map>
#include <random>
#include <string>

#include "kinograph/dynamics/kinematics.h"
#include "kinograph/graph/normal_equations.h"
#include "kinograph/planning/formulation/dfg_builder.h"
#include "kinograph/planning/formulation/initialization.h"
#include "kinograph/planning/formulation/planning_graph.h"
#include "kinograph/planning/solver/augmented_lagrangian.h"
#include "test_problems.h"

namespace kinograph::planning {
namespace {
using namespace testing;

// Linearizes two graphs made by `build` (one per thread count, since the dynamics factors keep
// their last evaluation) at `rounds` random perturbations of their start values, with one and
// with two threads; each pair is compared exactly. A fresh NormalEquations per round shares out
// its first linearization whenever the graph has enough factors, so every round runs in
// parallel.
template <class Build>
void expect_same_on_two_threads(const Build& build, const std::string& what, int rounds = 16) {
  PlanningGraph a = build(), b = build();
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.05);
  const Eigen::VectorXd start = a.values.vector();
  for (int round = 0; round < rounds; ++round) {
    for (Eigen::Index i = 0; i < start.size(); ++i) a.values.vector()[i] = start[i] + noise(rng);
    b.values.vector() = a.values.vector();
    graph::NormalEquations one(a.graph, a.values, graph::OrderingMethod::kColamd, 1);
    graph::NormalEquations two(b.graph, b.values, graph::OrderingMethod::kColamd, 2);
    double e1 = 0, e2 = 0;
    ASSERT_TRUE(one.linearize(a.graph, a.values, &e1, nullptr)) << what;
    ASSERT_TRUE(two.linearize(b.graph, b.values, &e2, nullptr)) << what;
    ASSERT_EQ(e1, e2) << what << ", round " << round;
    ASSERT_EQ(one.hessian(), two.hessian()) << what << ", round " << round;
    ASSERT_EQ(one.gradient(), two.gradient()) << what << ", round " << round;
  }
}

TEST(ParallelLinearization, IiwaCondensedAndDfgWithPoseGoalAndTorqueTerm) {
  Problem p = iiwa_swing(40);
  Eigen::VectorXd tip(7);
  tip << 0.9, 0.5, 0.2, -1.0, 0.1, 1.0, 0.2;
  dynamics::Data data(*p.model);
  dynamics::forward_kinematics(*p.model, data, tip);
  p.goal.kind = Goal::Kind::kPose;
  p.goal.frame = "iiwa_link_ee_kuka";
  p.goal.pose = dynamics::frame_pose(*p.model, data, p.model->frame_index(p.goal.frame));
  p.objectives.min_torque = 0.01;
  const Trajectory init = straight_line(p, tip);
  expect_same_on_two_threads([&] { return build_graph(p, init); }, "iiwa condensed");
  expect_same_on_two_threads(
      [&] {
        PlanningGraph pg = build_graph(p, init);
        use_dfg_dynamics(pg, p);
        return pg;
      },
      "iiwa dfg");
}

TEST(ParallelLinearization, AcrobotWithBetweenKnotDynamics) {
  const Problem p = acrobot_swingup();
  const Trajectory init = straight_line(p, p.goal.q);
  expect_same_on_two_threads([&] { return build_graph(p, init); }, "acrobot");
}

// The same for a problem with obstacles, from its straight line to the goal.
void expect_same_with_collision_rows(const Problem& p, const std::string& what) {
  const Trajectory init = straight_line(p, p.goal.q);
  expect_same_on_two_threads(
      [&] {
        PlanningGraph pg = build_graph(p, init);
        EXPECT_FALSE(pg.collision.empty());
        return pg;
      },
      what);
}

TEST(ParallelLinearization, IiwaAtTheDeskWithCollisionAndSelfCollisionHinges) {
  expect_same_with_collision_rows(
      load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml").problem,
      "iiwa at the desk");
}

TEST(ParallelLinearization, RrWithCollisionHinges) {
  expect_same_with_collision_rows(rr_reach(), "rr with a ball");
}

// worst_constraint evaluates the factors on the process's workers: the row it reports is the
// first of the worst in the factors' order, as a scan on one thread finds it, and the multiplier
// update (on the caller's thread) reports the same row and updates every factor's multipliers.
TEST(ParallelLinearization, ConstraintScansAreTheSerialOnes) {
  const Problem p =
      load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/iiwa_desk.yaml").problem;
  PlanningGraph pg = build_graph(p, straight_line(p, p.goal.q));
  const std::vector<const FactorEntry*> constraints = pg.constraints(false);
  ASSERT_GE(constraints.size(), 64u);  // enough to be shared out by worst_constraint
  ConstraintState state;
  AugmentedLagrangian al(constraints, state);
  std::map<FactorKey, Multipliers> serial;  // copies, updated on this thread
  for (const FactorEntry* e : constraints) serial.emplace(e->key, state.at(e->key));
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.05);
  const Eigen::VectorXd start = pg.values.vector();
  for (int round = 0; round < 4; ++round) {
    for (Eigen::Index i = 0; i < start.size(); ++i) pg.values.vector()[i] = start[i] + noise(rng);
    ConstrainedFactor::Violation first;
    const FactorEntry* worst = nullptr;
    for (const FactorEntry* e : constraints) {
      const ConstrainedFactor::Violation v = e->constrained->check(pg.values);
      if (v.scaled > first.scaled) {
        first = v;
        worst = e;
      }
    }
    ASSERT_NE(worst, nullptr) << "round " << round;  // the noise breaks the collocation rows
    const ConstraintReport report = worst_constraint(constraints, pg.values);
    EXPECT_EQ(report.entry, worst) << "round " << round;
    EXPECT_EQ(report.row, first.row) << "round " << round;
    EXPECT_EQ(report.scaled_violation, first.scaled) << "round " << round;
    // The multipliers: λ ← λ + μc, factor by factor, against AugmentedLagrangian's update.
    for (const FactorEntry* e : constraints) {
      e->constrained->update_multipliers(pg.values, serial.at(e->key));
    }
    const ConstraintReport updated = al.update_unless_within(pg.values, -1);
    EXPECT_EQ(updated.entry, worst) << "round " << round;
    for (const FactorEntry* e : constraints) {
      ASSERT_EQ(state.at(e->key).lower, serial.at(e->key).lower) << "round " << round;
      ASSERT_EQ(state.at(e->key).upper, serial.at(e->key).upper) << "round " << round;
    }
    for (auto& [key, m] : serial) m.penalty = state.penalty();  // μ as the update left it
  }
}

}  // namespace
}  // namespace kinograph::planning

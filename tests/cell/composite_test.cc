// The centralized problem of a cell: its self pairs (each robot's own, minus its allowed ones,
// plus every pair across robots), and a two-arm plan whose split plans validate one by one and
// keep the arms apart by an independent walk over every pair of their shapes.
#include "kinograph/cell/composite_problem.h"

#include <gtest/gtest.h>

#include <set>

#include "kinograph/collision/collision_world.h"
#include "kinograph/collision/convex_shape.h"
#include "kinograph/collision/pair_distance.h"
#include "kinograph/collision/shape.h"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/clearance_world.h"
#include "kinograph/planning/trajectory_sampler.h"
#include "kinograph/planning/validate.h"

namespace kinograph::cell {
namespace {

const std::string kCells = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/cells/";

// Robot index of a composite geometry.
int robot_of(const std::vector<dynamics::ComposedRange>& ranges, int geometry) {
  for (std::size_t r = 0; r < ranges.size(); ++r) {
    if (geometry >= ranges[r].collision_offset &&
        geometry < ranges[r].collision_offset + ranges[r].collision_count)
      return static_cast<int>(r);
  }
  return -1;
}

TEST(CompositeTest, SelfPairsAreEachRobotsOwnAndAllAcrossRobots) {
  const Cell cell = load_cell(kCells + "two_iiwa_table.yaml");
  const CompositeProblem cp = composite_problem(cell);
  const dynamics::Model& m = *cp.problem.model;
  collision::CollisionWorld world(m, planning::self_pair_options(cp.problem));
  const std::set<std::pair<int, int>> pairs(world.self_pairs().begin(), world.self_pairs().end());
  std::set<std::pair<int, int>> expected;
  for (std::size_t r = 0; r < cell.robots.size(); ++r) {
    const planning::Problem& own = cell.robots[r].scene.problem;
    collision::CollisionWorld own_world(*own.model, planning::self_pair_options(own));
    const int o = cp.ranges[r].collision_offset;
    for (const auto& [a, b] : own_world.self_pairs()) expected.insert({a + o, b + o});
  }
  const auto first_body = [&](int r) { return cp.ranges[r].offset; };
  for (int a = 0; a < static_cast<int>(m.collision.size()); ++a) {
    for (int b = a + 1; b < static_cast<int>(m.collision.size()); ++b) {
      const int ra = robot_of(cp.ranges, a), rb = robot_of(cp.ranges, b);
      if (ra == rb) continue;
      const int ba = m.collision[a].body, bb = m.collision[b].body;
      // Bases share the composite's fixed base: base-base and base-first-link are not pairs.
      if (ba < 0 && bb < 0) continue;
      if ((ba < 0 && bb == first_body(rb)) || (bb < 0 && ba == first_body(ra))) continue;
      expected.insert({a, b});
    }
  }
  EXPECT_EQ(pairs, expected);
  EXPECT_GT(pairs.size(), 100u);
}

TEST(CompositeTest, SplitAndJoinRoundTrip) {
  const Cell cell = load_cell(kCells + "two_iiwa_table.yaml");
  const CompositeProblem cp = composite_problem(cell);
  planning::Plan plan;
  plan.t = {0.0, 0.5, 1.0};
  for (Eigen::MatrixXd* x : {&plan.q, &plan.qd, &plan.qdd, &plan.tau})
    *x = Eigen::MatrixXd::Random(3, 14);
  std::vector<planning::Plan> parts;
  for (const dynamics::ComposedRange& r : cp.ranges) parts.push_back(robot_plan(plan, r));
  EXPECT_EQ(parts[1].q, plan.q.rightCols(7));
  const planning::Plan joined = composite_plan(parts, cp.ranges);
  EXPECT_EQ(joined.q, plan.q);
  EXPECT_EQ(joined.tau, plan.tau);
  parts[1].t[1] = 0.6;
  EXPECT_THROW(composite_plan(parts, cp.ranges), std::invalid_argument);
}

TEST(CompositeTest, PoseGoalIsRefusedUntilResolved) {
  Cell cell = load_cell(kCells + "two_iiwa_table.yaml");
  cell.robots[1].scene.problem.goal.kind = planning::Goal::Kind::kPose;
  try {
    composite_problem(cell);
    FAIL() << "a pose goal was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("robot 'arm1' has a pose goal"), std::string::npos);
  }
}

// The smallest distance between any shape of robot a and any shape of robot b (bases
// included) over the plans, sampled 20 times per interval on the interpolant.
double min_distance_between(const Cell& cell, const std::vector<planning::Plan>& plans, int a,
                            int b) {
  const dynamics::Model& ma = *cell.robots[a].scene.problem.model;
  const dynamics::Model& mb = *cell.robots[b].scene.problem.model;
  const planning::SampledPath pa = planning::sample_plan(ma, plans[a], 20);
  const planning::SampledPath pb = planning::sample_plan(mb, plans[b], 20);
  EXPECT_EQ(pa.t, pb.t);
  dynamics::Data da(ma), db(mb);
  const auto world_pose = [](const dynamics::Geometry& g, const dynamics::Data& d) {
    return g.body < 0 ? g.origin : Eigen::Isometry3d(d.body_pose[g.body] * g.origin);
  };
  std::vector<collision::ConvexShape> sa, sb;
  for (const dynamics::Geometry& g : ma.collision) sa.emplace_back(collision::shape_of(g));
  for (const dynamics::Geometry& g : mb.collision) sb.emplace_back(collision::shape_of(g));
  double lowest = std::numeric_limits<double>::infinity();
  for (Eigen::Index k = 0; k < pa.q.rows(); ++k) {
    dynamics::forward_kinematics(ma, da, pa.q.row(k).transpose());
    dynamics::forward_kinematics(mb, db, pb.q.row(k).transpose());
    for (std::size_t i = 0; i < ma.collision.size(); ++i) {
      for (std::size_t j = 0; j < mb.collision.size(); ++j) {
        const collision::PairDistance d = collision::pair_distance(
            sa[i], world_pose(ma.collision[i], da), sb[j], world_pose(mb.collision[j], db));
        if (d.valid) lowest = std::min(lowest, d.distance);
      }
    }
  }
  return lowest;
}

TEST(CompositeTest, TwoArmCellPlansAndItsArmsStayApart) {
  const Cell cell = load_cell(kCells + "two_iiwa_table.yaml");
  const CompositeProblem cp = composite_problem(cell);
  const planning::Plan plan = planning::BatchPlanner().plan(cp.problem);
  ASSERT_TRUE(plan.success()) << planning::to_string(plan.stats.status) << ": "
                              << plan.stats.reason;
  std::vector<planning::Plan> own;
  for (std::size_t r = 0; r < cell.robots.size(); ++r) {
    own.push_back(robot_plan(plan, cp.ranges[r]));
    const planning::Validation v = planning::validate(cell.robots[r].scene.problem, own.back());
    EXPECT_TRUE(v.valid) << cell.robots[r].name << ": "
                         << (v.failures.empty() ? "" : v.failures.front());
  }
  EXPECT_GE(min_distance_between(cell, own, 0, 1), 0.0);
}

TEST(CompositeTest, TwoArmCellCrossesWhenEachArmPlansAlone) {
  // What makes the cell a test: each arm planned as if it were alone hits the other.
  const Cell cell = load_cell(kCells + "two_iiwa_table.yaml");
  std::vector<planning::Plan> alone;
  for (const CellRobot& robot : cell.robots) {
    alone.push_back(planning::BatchPlanner().plan(robot.scene.problem));
    ASSERT_TRUE(alone.back().success()) << robot.name;
  }
  EXPECT_LT(min_distance_between(cell, alone, 0, 1), 0.0);
}

}  // namespace
}  // namespace kinograph::cell

// The four ring scenes (robots/scenes/iiwa_ring_*.yaml) are a fair crossing problem for robots
// that plan around each other: every goal is clear of every other arm's start and goal by the
// planner's margin (a robot held still at its start never stands on a goal), and the four
// straight joint-space motions, run together, collide (so the arms must coordinate).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "kinograph/fleet/joint_clearance.h"
#include "kinograph/planning/io/scene.h"

namespace kinograph::fleet {
namespace {

std::vector<planning::Scene> ring() {
  std::vector<planning::Scene> scenes;
  for (const char* arm : {"a", "b", "c", "d"}) {
    scenes.push_back(planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) +
                                          "/robots/scenes/iiwa_ring_" + arm + ".yaml"));
  }
  return scenes;
}

// The straight line from `from` to `to` over `horizon` s in `steps` intervals.
planning::Plan line(const Eigen::VectorXd& from, const Eigen::VectorXd& to, double horizon,
                    int steps) {
  planning::Plan p;
  p.q = p.qd = p.qdd = p.tau = Eigen::MatrixXd::Zero(steps + 1, from.size());
  for (int k = 0; k <= steps; ++k) {
    const double s = static_cast<double>(k) / steps;
    p.t.push_back(s * horizon);
    p.q.row(k) = ((1 - s) * from + s * to).transpose();
  }
  return p;
}

RobotPlan standing(const planning::Scene& scene, const Eigen::VectorXd& q) {
  return {scene.problem.name, scene.problem.model, line(q, q, 1.0, 1), 0.0};
}

TEST(RingScenes, EveryGoalIsClearOfTheOtherArmsStartsAndGoals) {
  const std::vector<planning::Scene> scenes = ring();
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const double margin = scenes[i].problem.objectives.collision_epsilon;
    for (std::size_t j = 0; j < scenes.size(); ++j) {
      if (i == j) continue;
      for (const bool at_goal : {false, true}) {
        const Eigen::VectorXd& other =
            at_goal ? scenes[j].problem.goal.q : scenes[j].problem.start_q;
        const JointClearance c = joint_clearance(
            {standing(scenes[i], scenes[i].problem.goal.q), standing(scenes[j], other)});
        EXPECT_GE(c.min_distance, margin)
            << scenes[i].problem.name << "'s goal and " << scenes[j].problem.name << "'s "
            << (at_goal ? "goal" : "start") << ": " << describe(c);
      }
    }
  }
}

TEST(RingScenes, TheStraightMotionsTogetherCollide) {
  const std::vector<planning::Scene> scenes = ring();
  std::vector<RobotPlan> robots;
  for (const planning::Scene& s : scenes) {
    robots.push_back({s.problem.name, s.problem.model,
                      line(s.problem.start_q, s.problem.goal.q, s.problem.horizon, s.problem.steps),
                      0.0});
  }
  const JointClearance c = joint_clearance(robots);
  EXPECT_LT(c.min_distance, 0.0) << describe(c);
}

}  // namespace
}  // namespace kinograph::fleet

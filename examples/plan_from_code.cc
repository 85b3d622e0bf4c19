// Poses a planning problem in code (the planar RR arm swinging past a ball), plans it with the
// batch planner, writes the plan file and reads it back.
// Usage: plan_from_code OUT.json   (exit 0 when the plan validates and reads back whole)
#include <iostream>
#include <memory>
#include <optional>

#include "kinograph/collision/obstacle.h"
#include "kinograph/collision/shape.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/io/plan_json.h"
#include "kinograph/planning/io/scene.h"

namespace kp = kinograph::planning;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: plan_from_code OUT.json\n";
    return 2;
  }
  const std::string out = argv[1];
  try {
    // Shipped robots are found in the installed data directory (or $KINOGRAPH_DATA_DIR).
    const std::optional<std::string> urdf =
        kp::resolve_scene_path("robots/rr/rr.urdf", EXAMPLE_KINOGRAPH_DATA_DIR);
    if (!urdf) {
      std::cerr << "plan_from_code: robots/rr/rr.urdf is not in " << EXAMPLE_KINOGRAPH_DATA_DIR
                << "\n";
      return 1;
    }
    kp::Scene scene;  // the problem plus what the plan file names (robot file, obstacle names)
    scene.urdf = scene.urdf_path = *urdf;
    kp::Problem& problem = scene.problem;
    problem.name = "rr_past_a_ball";
    problem.model = std::make_shared<const kinograph::dynamics::Model>(
        kinograph::dynamics::Model::from_urdf_file(*urdf));
    problem.horizon = 3.0;  // s
    problem.steps = 30;
    problem.start_q = Eigen::Vector2d(-1.2, 0.0);
    problem.start_qd = Eigen::Vector2d::Zero();
    problem.goal.q = Eigen::Vector2d(1.2, 0.0);
    kinograph::collision::Obstacle ball;
    ball.id = 0;
    ball.shape = kinograph::collision::Shape::sphere(0.12);
    ball.pose.translation() = Eigen::Vector3d(0.1, 0.0, 1.9);  // just above the upright tip
    problem.obstacles.push_back(ball);
    scene.obstacle_names.push_back("ball");

    const kp::Plan plan = kp::BatchPlanner().plan(problem);
    std::cout << kp::summarize(plan);
    kp::write_plan(plan, scene, out);

    const kp::PlanFile back = kp::read_plan_file(out);
    std::cout << "read back " << out << ": robot " << back.model->name << ", " << back.plan.q.rows()
              << " states, obstacle '" << back.info.obstacle_names.at(0) << "', final q = ["
              << back.plan.q.bottomRows(1) << "]\n";
    if (!plan.success()) return 1;
    return back.plan.q.isApprox(plan.q, 1e-9) ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "plan_from_code: " << e.what() << "\n";
    return 1;
  }
}

#include "kinograph/cell/composite_problem.h"

#include <stdexcept>

namespace kinograph::cell {
namespace {

std::string robot_text(const CellRobot& robot) { return "robot '" + robot.name + "'"; }

}  // namespace

CompositeProblem composite_problem(const Cell& cell) {
  if (cell.robots.empty()) throw std::invalid_argument("the cell has no robots");
  CompositeProblem out;
  std::vector<dynamics::ComposedPart> parts;
  for (const CellRobot& robot : cell.robots) {
    // The scene placed the robot at its base already.
    parts.push_back({robot.name, robot.scene.problem.model.get(), Eigen::Isometry3d::Identity()});
  }
  auto model = std::make_shared<const dynamics::Model>(dynamics::compose(parts, &out.ranges));
  const planning::Problem& first = cell.robots.front().scene.problem;
  planning::Problem& p = out.problem;
  p.name = cell.name;
  p.model = model;
  p.horizon = first.horizon;
  p.steps = first.steps;
  p.obstacles = first.obstacles;
  p.objectives = first.objectives;
  out.obstacle_names = cell.robots.front().scene.obstacle_names;
  p.start_q.resize(model->nq());
  p.start_qd.resize(model->nq());
  p.goal.kind = planning::Goal::Kind::kJoint;
  p.goal.q.resize(model->nq());
  p.self_and_floor.self_collision = true;
  p.self_and_floor.floor = first.self_and_floor.floor;
  for (std::size_t i = 0; i < cell.robots.size(); ++i) {
    const CellRobot& robot = cell.robots[i];
    const planning::Problem& rp = robot.scene.problem;
    const dynamics::ComposedRange& range = out.ranges[i];
    if (rp.goal.kind != planning::Goal::Kind::kJoint) {
      throw std::invalid_argument(robot_text(robot) +
                                  " has a pose goal; the centralized planner needs joint goals "
                                  "(resolve_pose_goals)");
    }
    if (rp.self_and_floor.floor != p.self_and_floor.floor) {
      throw std::invalid_argument(robot_text(robot) + " stands on another floor than robot '" +
                                  cell.robots.front().name +
                                  "' (each robot's floor defaults to its mounting face): give "
                                  "the cell a 'floor'");
    }
    p.start_q.segment(range.offset, range.nq) = rp.start_q;
    p.start_qd.segment(range.offset, range.nq) = rp.start_qd;
    p.goal.q.segment(range.offset, range.nq) = rp.goal.q;
    const auto shift = [&](int body) { return body < 0 ? body : body + range.offset; };
    for (const auto& [a, b] : rp.self_and_floor.allowed_pairs) {
      p.self_and_floor.allowed_pairs.emplace_back(shift(a), shift(b));
    }
    if (!rp.self_and_floor.self_collision) {  // none of its own pairs is checked
      for (int a = -1; a < range.nq; ++a) {
        for (int b = a + 1; b < range.nq; ++b) {
          p.self_and_floor.allowed_pairs.emplace_back(shift(a), shift(b));
        }
      }
    }
    for (planning::TaskConstraint task : rp.task_constraints) {
      task.frame = dynamics::composed_name(robot.name, task.frame);
      p.task_constraints.push_back(std::move(task));
    }
  }
  return out;
}

void resolve_pose_goals(Cell& cell, const planning::BatchPlanner& planner) {
  for (CellRobot& robot : cell.robots) {
    planning::Problem& p = robot.scene.problem;
    if (p.goal.kind == planning::Goal::Kind::kJoint) continue;
    const planning::Plan alone = planner.plan(p);
    if (!alone.success()) {
      const std::string why =
          alone.validation.failures.empty() ? alone.stats.reason : alone.validation.failures[0];
      throw std::invalid_argument(robot_text(robot) + ": its pose goal (frame '" + p.goal.frame +
                                  "') has no joint goal: planned alone, " + why);
    }
    p.goal = planning::Goal{};
    p.goal.q = alone.q.row(alone.q.rows() - 1).transpose();
  }
}

planning::Plan robot_plan(const planning::Plan& composite, const dynamics::ComposedRange& range) {
  planning::Plan plan;
  plan.t = composite.t;
  plan.q = composite.q.middleCols(range.offset, range.nq);
  plan.qd = composite.qd.middleCols(range.offset, range.nq);
  plan.qdd = composite.qdd.middleCols(range.offset, range.nq);
  plan.tau = composite.tau.middleCols(range.offset, range.nq);
  plan.stats = composite.stats;
  return plan;
}

planning::Plan composite_plan(const std::vector<planning::Plan>& plans,
                              const std::vector<dynamics::ComposedRange>& ranges) {
  if (plans.size() != ranges.size() || plans.empty()) {
    throw std::invalid_argument("composite_plan: " + std::to_string(plans.size()) + " plans for " +
                                std::to_string(ranges.size()) + " robots");
  }
  const int nq = ranges.back().offset + ranges.back().nq;
  const Eigen::Index rows = static_cast<Eigen::Index>(plans.front().t.size());
  planning::Plan out;
  out.t = plans.front().t;
  out.stats = plans.front().stats;
  for (Eigen::MatrixXd* m : {&out.q, &out.qd, &out.qdd, &out.tau}) m->resize(rows, nq);
  for (std::size_t i = 0; i < plans.size(); ++i) {
    const planning::Plan& plan = plans[i];
    const dynamics::ComposedRange& r = ranges[i];
    bool same_times = plan.t.size() == out.t.size();
    for (std::size_t k = 0; same_times && k < plan.t.size(); ++k) {
      same_times = std::abs(plan.t[k] - out.t[k]) <= 1e-9;
    }
    if (!same_times) {
      throw std::invalid_argument("composite_plan: robot '" + r.name +
                                  "'s plan has other times than robot '" + ranges[0].name + "'s");
    }
    if (plan.q.rows() != rows || plan.q.cols() != r.nq || plan.qd.cols() != r.nq ||
        plan.qdd.cols() != r.nq || plan.tau.cols() != r.nq) {
      throw std::invalid_argument("composite_plan: robot '" + r.name + "'s plan is not " +
                                  std::to_string(rows) + " states of " + std::to_string(r.nq) +
                                  " joints");
    }
    out.q.middleCols(r.offset, r.nq) = plan.q;
    out.qd.middleCols(r.offset, r.nq) = plan.qd;
    out.qdd.middleCols(r.offset, r.nq) = plan.qdd;
    out.tau.middleCols(r.offset, r.nq) = plan.tau;
  }
  return out;
}

}  // namespace kinograph::cell

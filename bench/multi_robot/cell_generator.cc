#include "bench/multi_robot/cell_generator.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "kinograph/cell/cell.h"
#include "kinograph/cell/composite_problem.h"
#include "kinograph/collision/collision_world.h"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/goal_sampler.h"
#include "kinograph/planning/problem_check.h"

namespace kinograph::bench {
namespace {

// Where the robots stand: base i at radius r, facing the centre (two arms: across a box table).
struct Layout {
  double radius;
  std::string table;
};

Layout layout(int n) {
  if (n == 2) {
    return {0.65, "{id: table, shape: box, size: [0.5, 0.9, 0.45], position: [0, 0, 0.225]}"};
  }
  const double r = n <= 4 ? 0.9 : 1.1;
  return {r, fmt::format("{{id: table, shape: cylinder, size: [{:.2f}, 0.45], "
                         "position: [0, 0, 0.225]}}",
                         r - 0.45)};
}

// Hand regions in the robot's base frame (x towards the table's centre, y to its left).
struct Region {
  double x0, x1, y0, y1, z0, z1;
  bool contains(const Eigen::Vector3d& p) const {
    return p.x() >= x0 && p.x() <= x1 && p.y() >= y0 && p.y() <= y1 && p.z() >= z0 && p.z() <= z1;
  }
};
constexpr Region kStart{0.45, 0.72, 0.05, 0.35, 0.50, 0.90};
constexpr Region kGoal{0.45, 0.72, -0.35, -0.05, 0.50, 0.90};

std::string vector_text(const Eigen::VectorXd& q) {
  std::string s = "[";
  for (Eigen::Index i = 0; i < q.size(); ++i) s += fmt::format("{}{:.4f}", i ? ", " : "", q[i]);
  return s + "]";
}

std::string cell_text(const CellGeneratorOptions& o, const std::string& name,
                      const std::vector<Eigen::VectorXd>& starts,
                      const std::vector<Eigen::VectorXd>& goals) {
  const Layout l = layout(o.robots);
  const std::string srdf = (std::filesystem::path(o.urdf).parent_path() / "iiwa14.srdf").string();
  std::string s = fmt::format(
      "# {} iiwa 14 arms {}.\n"
      "# Crossing goals: each hand goes from its robot's left to its right over the table, and\n"
      "# the arms' straight joint-space lines collide. Drawn by bench/multi_robot:\n"
      "# multi_robot_bench --write-cell FILE --robots {} --seed {}\n"
      "name: {}\nhorizon: {}\nsteps: {}\nfloor: {{enabled: true, height: 0}}\n"
      "obstacles:\n  - {}\nobjectives: {{collision_epsilon: 0.05, limit_epsilon: 0.03}}\n"
      "camera: {{eye: [{:.2f}, {:.2f}, {:.2f}], target: [0, 0, 0.5], up: [0, 0, 1], "
      "fov_y_deg: 40}}\nrobots:\n",
      o.robots,
      o.robots == 2
          ? "facing each other across a table, bases 1.3 m apart"
          : fmt::format("on a circle of radius {} m around a round table, facing its centre",
                        l.radius),
      o.robots, o.seed, name, o.horizon, o.steps, l.table, 0.5 * (l.radius + 1.2),
      -1.4 * (l.radius + 0.9), 0.9 * (l.radius + 1.0));
  for (int i = 0; i < o.robots; ++i) {
    const double angle = 2 * M_PI * i / o.robots + M_PI;  // robot 0 on the −x side
    s += fmt::format(
        "  - name: arm{}\n    robot:\n      urdf: {}\n      srdf: {}\n"
        "      base: {{position: [{:.4f}, {:.4f}, 0], rpy: [0, 0, {:.6f}]}}\n"
        "    start: {{q: {}}}\n    goal: {{q: {}}}\n",
        i, o.urdf, srdf, l.radius * std::cos(angle), l.radius * std::sin(angle), angle - M_PI,
        vector_text(starts[i]), vector_text(goals[i]));
  }
  return s;
}

// Cross-robot clearance at one composite configuration: only pairs of different robots.
class CrossCheck {
 public:
  explicit CrossCheck(const cell::CompositeProblem& cp) : model_(*cp.problem.model), data_(model_) {
    collision::CollisionWorldOptions o;
    o.self_collision = true;
    for (const dynamics::ComposedRange& r : cp.ranges) {
      for (int a = -1; a < r.nq; ++a) {
        for (int b = a + 1; b < r.nq; ++b) {
          o.self_collision_excluded.emplace_back(a < 0 ? -1 : a + r.offset, b + r.offset);
        }
      }
    }
    world_ = std::make_unique<collision::CollisionWorld>(model_, o);
  }
  bool clear(const Eigen::VectorXd& q, double distance) {
    dynamics::forward_kinematics(model_, data_, q);
    return !world_->any_within(data_, 0.0, distance);
  }

 private:
  const dynamics::Model& model_;
  dynamics::Data data_;
  std::unique_ptr<collision::CollisionWorld> world_;
};

Eigen::VectorXd rounded(const Eigen::VectorXd& q) { return (q * 1e4).array().round() / 1e4; }

// Draws every robot's start (pass 0) or goal (pass 1) into `chosen`, each clear of those drawn
// before it (the others standing upright); false when one cannot be drawn.
bool draw_poses(const cell::Cell& c, const cell::CompositeProblem& cp, CrossCheck& cross,
                const CellGeneratorOptions& o, std::uint64_t seed, int pass,
                std::vector<Eigen::VectorXd>& chosen) {
  const Region& region = pass == 0 ? kStart : kGoal;
  Eigen::VectorXd all = Eigen::VectorXd::Zero(cp.problem.model->nq());
  for (int i = 0; i < o.robots; ++i) {
    const planning::Problem& p = c.robots[i].scene.problem;
    planning::GoalSamplerOptions so;
    so.seed = seed * 1000003 + static_cast<std::uint64_t>(i) * 7919 + pass;
    so.self_collision_excluded = p.self_and_floor.allowed_pairs;
    planning::GoalSampler sampler(p, so);
    const dynamics::Model& m = *p.model;
    dynamics::Data d(m);
    const int ee = m.frame_index("iiwa_link_ee");
    const Eigen::Isometry3d base_inv = c.robots[i].scene.base.inverse();
    bool found = false;
    for (int draw = 0; draw < o.max_draws && !found; ++draw) {
      const std::optional<Eigen::VectorXd> q = sampler.sample();
      if (!q) break;
      const Eigen::VectorXd qr = rounded(*q);
      if (!sampler.accepts(qr)) continue;
      dynamics::forward_kinematics(m, d, qr);
      if (!region.contains(base_inv * dynamics::frame_pose(m, d, ee).translation())) continue;
      Eigen::VectorXd trial = all;
      trial.segment(cp.ranges[i].offset, 7) = qr;
      if (!cross.clear(trial, o.robot_clearance)) continue;
      chosen[i] = qr;
      all = trial;
      found = true;
    }
    if (!found) return false;
  }
  return true;
}

// True when the robots' straight joint-space lines, run at the same time, bring two robots
// into contact: the problem needs coordination.
bool lines_collide(const cell::CompositeProblem& cp, CrossCheck& cross,
                   const std::vector<Eigen::VectorXd>& starts,
                   const std::vector<Eigen::VectorXd>& goals) {
  Eigen::VectorXd a(cp.problem.model->nq()), b(cp.problem.model->nq());
  for (std::size_t i = 0; i < cp.ranges.size(); ++i) {
    a.segment(cp.ranges[i].offset, 7) = starts[i];
    b.segment(cp.ranges[i].offset, 7) = goals[i];
  }
  constexpr int kSamples = 40;
  for (int k = 1; k < kSamples; ++k) {
    if (!cross.clear(a + (b - a) * k / double(kSamples), 0.0)) return true;
  }
  return false;
}

}  // namespace

std::string generate_cell(const CellGeneratorOptions& o, const std::string& name) {
  if (o.robots < 2) throw std::invalid_argument("generate_cell: at least two robots");
  // A cell with every arm upright gives the robots' scenes and the composite to check against.
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(7);
  std::vector<Eigen::VectorXd> starts(o.robots, zero), goals(o.robots, zero);
  const cell::Cell c = cell::parse_cell(cell_text(o, name, starts, goals), o.path);
  const cell::CompositeProblem cp = cell::composite_problem(c);
  CrossCheck cross(cp);
  for (int attempt = 0; attempt < o.max_problems; ++attempt) {
    const std::uint64_t seed = o.seed * 1000 + static_cast<std::uint64_t>(attempt);
    if (!draw_poses(c, cp, cross, o, seed, 0, starts)) continue;
    if (!draw_poses(c, cp, cross, o, seed, 1, goals)) continue;
    if (!lines_collide(cp, cross, starts, goals)) continue;
    // The planner's own refusals (a horizon too short for a joint's move, ...) redraw too.
    const std::string text = cell_text(o, name, starts, goals);
    if (planning::check_problem(cell::composite_problem(cell::parse_cell(text, o.path)).problem)
            .empty()) {
      return text;
    }
  }
  throw std::runtime_error(
      fmt::format("generate_cell {}: no crossing problem of clear starts and goals in {} tries",
                  name, o.max_problems));
}

}  // namespace kinograph::bench

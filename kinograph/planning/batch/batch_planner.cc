#include "kinograph/planning/batch/batch_planner.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <sstream>

#include "kinograph/collision/collision_world.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/graph/levenberg_marquardt.h"
#include "kinograph/planning/formulation/initialization.h"

namespace kinograph::planning {
namespace {

std::string joint_list_outside(const dynamics::Model& model, const Eigen::VectorXd& q,
                               const char* what) {
  std::ostringstream os;
  for (int j = 0; j < model.nq(); ++j) {
    const auto& l = model.bodies[j].limits;
    if (q[j] < l.lower || q[j] > l.upper) {
      os << what << " joint '" << model.bodies[j].joint_name << "' = " << q[j] << " is outside ["
         << l.lower << ", " << l.upper << "]; ";
    }
  }
  return os.str();
}

double min_clearance(const Problem& problem, const Eigen::VectorXd& q) {
  collision::CollisionWorld world(*problem.model);
  for (const auto& o : problem.obstacles) world.add_obstacle(o);
  dynamics::Data data(*problem.model);
  dynamics::forward_kinematics(*problem.model, data, q);
  return world.closest(data, 0).distance;
}

Plan failed_plan(const Problem& problem, const std::string& status, const std::string& reason) {
  Plan plan;
  plan.stats.method = "batch-L";
  plan.stats.status = status;
  plan.stats.reason = reason;
  plan.validation.valid = false;
  plan.validation.failures.push_back(status + ": " + reason);
  (void)problem;
  return plan;
}

}  // namespace

std::string to_string(Formulation f) { return f == Formulation::kCondensed ? "condensed" : "dfg"; }

std::string check_problem(const Problem& p) {
  if (!p.model) return "problem has no robot model";
  const dynamics::Model& model = *p.model;
  const int n = model.nq();
  if (p.steps < 1) return "steps must be at least 1";
  if (!(p.horizon > 0) || !std::isfinite(p.horizon)) return "horizon must be positive and finite";
  if (p.start_q.size() != n)
    return "start_q has " + std::to_string(p.start_q.size()) + " entries, the robot has " +
           std::to_string(n) + " joints";
  if (p.start_qd.size() != 0 && p.start_qd.size() != n) return "start_qd has the wrong size";
  if (!p.start_q.allFinite() || !p.start_qd.allFinite()) return "start state holds NaN or inf";
  if (!(p.objectives.qc > 0) || !std::isfinite(p.objectives.qc)) return "Qc must be positive";
  if (!(p.objectives.min_torque >= 0) || !(p.objectives.collision_epsilon >= 0) ||
      !(p.objectives.limit_epsilon >= 0))
    return "objective weights and margins must be non-negative numbers";
  std::string r = joint_list_outside(model, p.start_q, "start");
  if (!r.empty()) return r;
  if (p.goal.kind == Goal::Kind::kJoint) {
    if (p.goal.q.size() != n) return "joint goal has the wrong size";
    if (!p.goal.q.allFinite()) return "joint goal holds NaN or inf";
    r = joint_list_outside(model, p.goal.q, "goal");
    if (!r.empty()) return r;
  } else {
    if (!p.goal.pose.matrix().allFinite()) return "goal pose holds NaN or inf";
    try {
      model.frame_index(p.goal.frame);
    } catch (const std::out_of_range&) {
      return "goal frame '" + p.goal.frame + "' is not in the model";
    }
  }
  for (const auto& t : p.task_constraints) {
    try {
      model.frame_index(t.frame);
    } catch (const std::out_of_range&) {
      return "task-constraint frame '" + t.frame + "' is not in the model";
    }
  }
  if (!p.obstacles.empty()) {
    try {
      if (min_clearance(p, p.start_q) < 0) return "the start configuration is in collision";
      if (p.goal.kind == Goal::Kind::kJoint && min_clearance(p, p.goal.q) < 0)
        return "the goal configuration is in collision";
    } catch (const std::exception& e) {
      return std::string("bad obstacle: ") + e.what();
    }
  }
  return "";
}

BatchPlanner::BatchPlanner(BatchPlannerOptions options) : options_(std::move(options)) {}

Plan BatchPlanner::plan(const Problem& problem, const Plan* warm) const {
  return plan(problem, warm, nullptr);
}

Plan BatchPlanner::plan(const Problem& problem, const Plan* warm, BatchSolution* solution) const {
  const auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&t0] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  const std::string method = warm != nullptr ? "batch-W" : "batch-L";
  const std::string problem_error = check_problem(problem);
  if (!problem_error.empty()) {
    Plan p = failed_plan(problem, "invalid_problem", problem_error);
    p.stats.method = method;
    p.stats.solve_time_s = elapsed();
    return p;
  }
  Trajectory init;
  Eigen::VectorXd q_goal;
  try {
    if (warm != nullptr) {
      init = warm_start(problem, *warm);
    } else {
      q_goal = *goal_configuration(problem);
      init = straight_line(problem, q_goal);
    }
  } catch (const std::exception& e) {
    Plan p = failed_plan(problem, "invalid_problem", e.what());
    p.stats.method = method;
    p.stats.solve_time_s = elapsed();
    return p;
  }
  // Initializations in the order tried: the straight line (or the warm start), then detours
  // around the obstacles (best clearance first). A straight line that runs through an obstacle
  // usually leads into a poor local minimum (e.g. straddling a thin tabletop), so when it collides
  // and the best detour does not, the detour goes first.
  std::vector<Trajectory> inits{init};
  const bool may_detour =
      warm == nullptr && options_.max_restarts > 0 && !problem.obstacles.empty();
  bool detours_added = false;
  auto add_detours = [&](bool detour_goes_first) {  // ranking costs queries: only when needed
    if (detours_added || !may_detour) return;
    detours_added = true;
    const std::vector<Detour> vias = detour_candidates(problem, q_goal, options_.detour);
    const size_t first = inits.size();
    for (int r = 0; r < options_.max_restarts && r < static_cast<int>(vias.size()); ++r) {
      inits.push_back(via_point(problem, vias[r].via, q_goal));
    }
    if (detour_goes_first && inits.size() > first && vias[0].clearance >= 0) {
      std::swap(inits[0], inits[first]);
    }
  };
  if (may_detour && options_.detour_first &&
      segment_clearance(problem, problem.start_q, q_goal, 2 * options_.detour.samples) < 0) {
    add_detours(true);
  }
  Plan best;
  SolveStats total;
  BatchSolution attempt;
  for (size_t a = 0; a < inits.size(); ++a) {
    Plan p = solve(problem, inits[a], method, solution != nullptr ? &attempt : nullptr);
    if (a == 0) {
      total = p.stats;
    } else {
      total.iterations += p.stats.iterations;
      total.outer_iterations += p.stats.outer_iterations;
      total.linear_solves += p.stats.linear_solves;
      ++total.attempts;
    }
    spdlog::debug("plan {}: attempt {}: {}", problem.name, a + 1,
                  p.success() ? "valid" : p.stats.status);
    const bool first = a == 0;
    if (first || p.success() ||
        p.stats.max_constraint_violation < best.stats.max_constraint_violation) {
      best = std::move(p);
      if (solution != nullptr) *solution = std::move(attempt);
    }
    if (best.success() || best.stats.status == "invalid_problem") break;
    add_detours(false);
  }
  const SolveStats own = best.stats;
  best.stats = total;
  best.stats.status = own.status;
  best.stats.reason = own.reason;
  best.stats.cost = own.cost;
  best.stats.max_constraint_violation = own.max_constraint_violation;
  best.stats.solve_time_s = elapsed();
  return best;
}

Plan BatchPlanner::solve(const Problem& problem, const Trajectory& init, const std::string& method,
                         BatchSolution* solution) const {
  const auto t0 = std::chrono::steady_clock::now();
  if (solution != nullptr) *solution = BatchSolution();  // empty unless the solve runs
  auto elapsed = [&t0] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  const int n = problem.model->nq(), N = problem.steps;

  PlanningGraph pg;
  std::vector<DfgConstraintStep> dfg_steps;
  try {
    pg = build_graph(problem, init, options_.graph);
    if (options_.formulation == Formulation::kDynamicFactorGraph) {
      dfg_steps = use_dfg_dynamics(pg, problem, options_.graph, options_.dfg);
    }
  } catch (const std::exception& e) {
    Plan p = failed_plan(problem, "invalid_problem", e.what());
    p.stats.method = method;
    return p;
  }
  AugmentedLagrangian al(pg.constraints, options_.augmented_lagrangian);
  const double tolerance = dfg_steps.empty() ? options_.constraint_tolerance
                                             : std::min(options_.constraint_tolerance,
                                                        options_.dfg_constraint_tolerance);
  const double tolerance_final = dfg_steps.empty() ? options_.inner_tolerance_final
                                                   : std::min(options_.inner_tolerance_final,
                                                              options_.dfg_inner_tolerance_final);

  graph::LevenbergMarquardtOptions lm_options;
  lm_options.record_history = false;
  lm_options.max_iterations = options_.max_inner_iterations;
  lm_options.relative_error_tol = options_.inner_tolerance_initial;
  graph::LevenbergMarquardt lm(lm_options);

  struct {
    double symbolic = 0, linearize = 0, factorize = 0, solve = 0, evaluate = 0, lm = 0, al = 0,
           lm_wall = 0;
  } timing;
  const double t_built = elapsed();
  SolveStats stats;
  stats.method = method;
  std::string status = "infeasible";
  std::string reason;
  double violation = 0;
  for (int outer = 0; outer < options_.max_outer_iterations; ++outer) {
    lm_options.max_iterations =
        std::min(options_.max_inner_iterations, options_.max_total_iterations - stats.iterations);
    if (lm_options.max_iterations <= 0) break;
    lm.set_options(lm_options);
    const double t_lm = elapsed();
    const graph::OptimizationResult r = lm.optimize(pg.graph, pg.values);
    timing.lm_wall += elapsed() - t_lm;
    timing.symbolic += r.symbolic_s;
    timing.linearize += r.linearize_s;
    timing.factorize += r.factorize_s;
    timing.solve += r.solve_s;
    timing.evaluate += r.evaluate_s;
    timing.lm += r.total_s;
    stats.iterations += r.iterations;
    stats.linear_solves += r.trials;
    stats.outer_iterations = outer + 1;
    if (r.status == graph::SolverStatus::kNonFinite) {
      status = "non_finite";
      reason = r.reason;
      break;
    }
    double t_al = elapsed();
    const ConstraintReport worst = al.report(pg.values);
    timing.al += elapsed() - t_al;
    violation = worst.scaled_violation;
    spdlog::debug("AL outer {}: mu={:.3g} LM {} its ({}), cost {:.6g}, worst {:.3g} at {}", outer,
                  al.penalty(), r.iterations, graph::to_string(r.status), r.final_error,
                  worst.scaled_violation, worst.where);
    if (violation <= tolerance && lm_options.relative_error_tol <= tolerance_final * 1.0001) {
      status = "converged";
      break;
    }
    if (violation <= tolerance) {
      // Feasible: one more solve at the final tolerance to settle the objective.
      lm_options.relative_error_tol = tolerance_final;
      t_al = elapsed();
      al.update(pg.values);
      timing.al += elapsed() - t_al;
      continue;
    }
    t_al = elapsed();
    al.update(pg.values);
    timing.al += elapsed() - t_al;
    lm_options.relative_error_tol = std::max(tolerance_final, lm_options.relative_error_tol * 0.1);
  }
  const double t_loop = elapsed();
  const ConstraintReport worst = al.report(pg.values);
  stats.max_constraint_violation = worst.violation;
  if (status == "infeasible" && worst.scaled_violation <= tolerance) {
    status = "converged";
  }
  if (status == "infeasible") {
    std::ostringstream os;
    os << "constraints still violated after " << stats.outer_iterations << " outer and "
       << stats.iterations << " LM iterations: worst " << worst.violation << " at " << worst.where;
    reason = os.str();
  }

  // The plan: trajectory from the values; τ from inverse dynamics in the condensed formulation
  // (which eliminates it, so it equals RNEA exactly), the DFG's own τ variables otherwise (so
  // the validator's dynamics residual checks the DFG's equations of motion).
  Plan plan = plan_from_trajectory(problem, read_trajectory(pg.values, N, n));
  for (const DfgConstraintStep& s : dfg_steps) {
    plan.tau.row(s.step) =
        dfg_torques(pg.values, *problem.model, s.step, options_.dfg.keys).transpose();
  }
  // Soft cost without the constraint terms: zero the penalty contributions by evaluating the
  // soft factors only.
  double soft = 0;
  for (const auto& f : pg.graph.factors()) {
    if (!f) continue;
    if (auto* c = dynamic_cast<const ConstrainedFactor*>(f.get())) {
      if (c->has_constraints()) {
        // Soft rows of mixed factors (min-torque) count; their constraint rows do not.
        Eigen::VectorXd z;
        c->values_at(pg.values, z);
        for (int i = 0; i < c->residual_dim(); ++i) {
          const RowSpec& row = c->rows()[i];
          if (row.kind == RowKind::kSoft)
            soft += 0.5 * std::pow(row.weight * (z[i] - row.lower), 2);
        }
        continue;
      }
    }
    soft += f->error(pg.values);
  }
  stats.cost = soft;
  stats.status = status;
  stats.reason = reason;
  plan.stats = stats;
  const double t_solved = elapsed();
  plan.validation = validate(problem, plan, options_.validation);
  plan.stats.solve_time_s = elapsed();
  spdlog::debug(
      "plan {}: build {:.1f} ms, LM {:.1f} ms (symbolic {:.1f}, linearize {:.1f}, factorize "
      "{:.1f}, "
      "solve {:.1f}, evaluate {:.1f}; wall {:.1f}), multipliers {:.1f} ms, rest of the loop {:.1f} "
      "ms, plan and cost {:.1f} ms, validate {:.1f} ms",
      problem.name, 1e3 * t_built, 1e3 * timing.lm, 1e3 * timing.symbolic, 1e3 * timing.linearize,
      1e3 * timing.factorize, 1e3 * timing.solve, 1e3 * timing.evaluate, 1e3 * timing.lm_wall,
      1e3 * timing.al, 1e3 * (t_loop - t_built - timing.lm_wall - timing.al),
      1e3 * (t_solved - t_loop), 1e3 * (plan.stats.solve_time_s - t_solved));
  if (solution != nullptr) {
    solution->penalty = al.penalty();
    solution->condensed = dfg_steps.empty();
    solution->graph = std::move(pg);
  }
  return plan;
}

}  // namespace kinograph::planning

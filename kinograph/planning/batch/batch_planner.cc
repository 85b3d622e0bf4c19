#include "kinograph/planning/batch/batch_planner.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>

#include "kinograph/graph/stopwatch.h"
#include "kinograph/planning/batch/grid_refinement.h"
#include "kinograph/planning/batch/interval_limits.h"
#include "kinograph/planning/formulation/initialization.h"
#include "kinograph/planning/solver/violation_text.h"

namespace kinograph::planning {

std::string to_string(Formulation f) { return f == Formulation::kCondensed ? "condensed" : "dfg"; }

Plan solved_plan(const Problem& problem, const PlanningGraph& pg, const OuterLoopResult& r,
                 const std::string& method, const BatchPlannerOptions& options) {
  Plan plan = plan_from_values(problem, pg.values, options.dfg.keys);
  plan.stats.method = method;
  plan.stats.status = r.status;
  plan.stats.reason = r.reason;
  plan.stats.iterations = r.iterations;
  plan.stats.outer_iterations = r.outer_iterations;
  plan.stats.linear_solves = r.linear_solves;
  plan.stats.max_constraint_violation = r.worst.violation;
  plan.stats.cost = soft_cost(pg.entries, pg.values);
  plan.stats.times = r.times;
  const auto t0 = std::chrono::steady_clock::now();
  plan.validation = validate(problem, plan, options.validation);
  plan.stats.times.validation_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return plan;
}

OuterLoopOptions outer_loop_options(const BatchPlannerOptions& options) {
  OuterLoopOptions loop = options.outer_loop;
  if (options.formulation == Formulation::kDynamicFactorGraph) {
    loop.constraint_tolerance =
        std::min(loop.constraint_tolerance, options.dfg_constraint_tolerance);
    loop.inner_tolerance_final =
        std::min(loop.inner_tolerance_final, options.dfg_inner_tolerance_final);
  }
  return loop;
}

namespace {

// The initial trajectory along a collision-free path, when one is found that fits the steps.
std::optional<Trajectory> searched_path(const Problem& problem, const Eigen::VectorXd& q_goal,
                                        const PathSearchOptions& options) {
  if (std::any_of(problem.obstacles.begin(), problem.obstacles.end(),
                  [](const collision::Obstacle& o) { return o.is_moving(); })) {
    return std::nullopt;  // the search sees obstacles at rest only
  }
  const std::optional<std::vector<Eigen::VectorXd>> path = search_path(problem, q_goal, options);
  if (!path || 2 * (path->size() - 1) > static_cast<size_t>(problem.steps)) return std::nullopt;
  return path_trajectory(problem, *path);
}

// Adds the work of `from` (add_work) and its attempts to `into`.
void add_counts(SolveStats& into, const SolveStats& from) {
  add_work(into, from);
  into.attempts += from.attempts;
}

}  // namespace

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
    Plan p = failed_plan(method, PlanStatus::kInvalidProblem, problem_error);
    p.stats.solve_time_s = elapsed();
    return p;
  }
  Trajectory init;
  Eigen::VectorXd q_goal;
  double initialization_s = 0;  // this call's own, outside the attempts' solves
  try {
    const graph::ScopedTimer timer(initialization_s);
    if (warm != nullptr) {
      init = warm_start(problem, *warm);
    } else {
      q_goal = *goal_configuration(problem);
      init = straight_line(problem, q_goal);
    }
  } catch (const std::exception& e) {
    Plan p = failed_plan(method, PlanStatus::kInvalidProblem, e.what());
    p.stats.solve_time_s = elapsed();
    return p;
  }
  // Initializations in the order tried: the straight line (or the warm start), then detours
  // around the obstacles (best clearance first) and a searched collision-free path. A straight
  // line that runs through an obstacle usually leads into a poor local minimum (e.g. straddling a
  // thin tabletop), so when it collides the best detour goes first if its path is clear, then the
  // searched path (made only when its turn comes: the search costs more than ranking detours).
  std::vector<std::optional<Trajectory>> inits{init};
  const bool may_detour =
      warm == nullptr && options_.max_restarts > 0 && !problem.obstacles.empty();
  const bool may_search = may_detour && options_.path_search.max_samples > 0;
  bool detours_added = false;
  // Adds the restarts; `tried` initializations are done. Returns whether the best detour went
  // first.
  auto add_restarts = [&](bool detour_goes_first, size_t tried) {
    if (detours_added || !may_detour) return false;
    const graph::ScopedTimer timer(initialization_s);
    detours_added = true;
    const int detours = options_.max_restarts - (may_search ? 1 : 0);
    const std::vector<Detour> vias = detour_candidates(problem, q_goal, options_.detour, detours);
    const size_t first = inits.size();
    for (int r = 0; r < static_cast<int>(vias.size()); ++r) {
      inits.push_back(via_point(problem, vias[r].via, q_goal));
    }
    const bool swapped = detour_goes_first && inits.size() > first && vias[0].clearance >= 0;
    if (swapped) std::swap(inits[0], inits[first]);
    if (may_search) inits.insert(inits.begin() + tried + (swapped ? 1 : 0), std::nullopt);
    return swapped;
  };
  bool straight_line_collides = false;
  if (may_detour && options_.detour_first) {
    const graph::ScopedTimer timer(initialization_s);
    straight_line_collides =
        segment_clearance(problem, problem.start_q, q_goal, 2 * options_.detour.samples) < 0;
  }
  if (straight_line_collides) add_restarts(true, 0);
  Plan best;
  SolveStats total;
  BatchSolution attempt;
  int made = 0;
  // Counts attempt `p` into the totals and keeps it when it is the best so far.
  auto consider = [&](Plan p) {
    const bool first = made++ == 0;
    if (first) {
      total = p.stats;
    } else {
      add_counts(total, p.stats);
    }
    spdlog::debug("plan {}: attempt {}: {}", problem.name, made,
                  p.success() ? std::string("valid") : to_string(p.stats.status));
    if (first || p.success() ||
        p.stats.max_constraint_violation < best.stats.max_constraint_violation) {
      best = std::move(p);
      if (solution != nullptr) *solution = std::move(attempt);
    }
  };
  // Grid refinement first: the straight line on a fine grid is a poor start (many variables,
  // each barely coupled to the objective), a coarse plan's interpolant a nearly feasible one.
  SolveStats coarse_stats;
  coarse_stats.attempts = 0;
  const int coarse_steps = warm == nullptr && options_.refine_max_interval > 0
                               ? coarser_grid(problem, options_.refine_max_interval)
                               : 0;
  if (coarse_steps > 0) {
    std::optional<Plan> p = solve_refined(problem, coarse_steps, method, coarse_stats,
                                          solution != nullptr ? &attempt : nullptr);
    if (p) consider(std::move(*p));
  }
  for (size_t a = 0; a < inits.size() && !best.success(); ++a) {
    if (!inits[a]) {
      const graph::ScopedTimer timer(initialization_s);
      inits[a] = searched_path(problem, q_goal, options_.path_search);
    }
    if (!inits[a]) continue;  // no path found: on to the next initialization
    consider(solve(problem, *inits[a], method, solution != nullptr ? &attempt : nullptr));
    if (best.success() || best.stats.status == PlanStatus::kInvalidProblem) break;
    add_restarts(false, a + 1);
  }
  if (!best.success() && best.stats.status != PlanStatus::kInvalidProblem && warm == nullptr &&
      !options_.effort_continuation.empty() && effort_continuation_applies(problem)) {
    consider(solve_by_effort_continuation(problem, q_goal, method,
                                          solution != nullptr ? &attempt : nullptr));
  }
  add_counts(total, coarse_stats);
  const SolveStats own = best.stats;
  best.stats = total;
  best.stats.status = own.status;
  best.stats.reason = own.reason;
  best.stats.cost = own.cost;
  best.stats.max_constraint_violation = own.max_constraint_violation;
  best.stats.times.initialization_s += initialization_s;
  best.stats.solve_time_s = elapsed();
  return best;
}

namespace {

// How close (a fraction of the limit) an interval's interpolant may come to a limit between
// the knots before its interior limit points join the graph: close enough that few intervals
// qualify, far enough that the re-solve rarely pushes an unlisted one over.
constexpr double kNearLimit = 0.1;
// Re-solves with more between-knot rows after the knot-only solve (the warm-up included); each
// adds the intervals the last one left near a limit, so few are ever needed.
constexpr int kMaxIntervalRounds = 5;

// How many of the problem's joints follow their dynamics between the knots.
int unactuated_count(const Problem& problem) {
  return static_cast<int>(std::count_if(problem.model->bodies.begin(), problem.model->bodies.end(),
                                        [](const dynamics::Body& b) { return !b.actuated; }));
}

// The interior limit rows of every interval (IntervalLimitRows bits): the union of `flags` and
// `near`; returns whether any was added.
bool add_flags(std::vector<char>& flags, const std::vector<char>& near) {
  bool added = false;
  for (size_t k = 0; k < flags.size(); ++k) {
    if ((near[k] & ~flags[k]) == 0) continue;
    flags[k] = static_cast<char>(flags[k] | near[k]);
    added = true;
  }
  return added;
}

// Carries the multipliers of the shooting-defect rows (the first `defect_rows` of every
// interval factor) into a record of the factor's new size, which bind() then keeps; the limit
// rows of a new layout start from zero.
void resize_interval_records(ConstraintState& state, const PlanningGraph& pg, int defect_rows) {
  for (const FactorEntry* e : pg.constraints(false)) {
    if (e->key.role != FactorRole::kInterval || !state.contains(e->key)) continue;
    Multipliers& m = state.at(e->key);
    const Eigen::Index rows = e->constrained->residual_dim(), old = m.lower.size();
    if (old == rows) continue;
    const Eigen::Index kept = std::min<Eigen::Index>({old, rows, defect_rows});
    Multipliers resized(static_cast<int>(rows), m.penalty);
    resized.lower.head(kept) = m.lower.head(kept);
    resized.upper.head(kept) = m.upper.head(kept);
    m = std::move(resized);
  }
}

}  // namespace

Plan BatchPlanner::solve(const Problem& problem, const Trajectory& init, const std::string& method,
                         BatchSolution* solution, bool from_interpolant) const {
  const auto t0 = std::chrono::steady_clock::now();
  if (solution != nullptr) *solution = BatchSolution();  // empty unless the solve runs
  // Between-knot rows by constraint generation: the knot-only graph first, then the intervals'
  // dynamics (unactuated joints) and interior limit points only where the interpolant of the
  // last solve comes near a limit, each re-solve warm from the last (multipliers included).
  // With unactuated joints the first re-solve integrates them in longer RK4 steps
  // (warmup_integration_step): it does most of the moving at a fraction of the price, and the
  // re-solve on the interpolant that follows is short.
  IntervalRows between;
  between.knots_only = true;
  between.limits.assign(static_cast<size_t>(problem.steps), 0);
  const bool shooting = unactuated_count(problem) > 0;
  PlanningGraph pg;
  ConstraintState state;
  OuterLoopResult r;
  SolveTimes own;  // the parts outside the outer loops: graphs and checks between the knots
  const double warmup_step = options_.warmup_integration_step;
  bool warmup = shooting && warmup_step > 0 &&
                integration_steps(problem.dt(), warmup_step) <
                    integration_steps(problem.dt(), kMaxIntegrationStep);
  if (from_interpolant) {  // no knot-only solve to leave the interpolant and come back to it
    between.knots_only = false;
    warmup = false;
    const graph::ScopedTimer timer(own.between_knot_checks_s);
    between.limits =
        intervals_near_limits(problem, plan_from_trajectory(problem, init), kNearLimit);
  }
  // This round's rows follow a converged solve that may already hold them all: limit rows
  // added to it, or the interpolant's rows after a converged warm-up.
  bool after_converged = false;
  for (int round = 0;; ++round) {
    PlanningGraph next;
    std::vector<DfgConstraintStep> dfg_steps;
    try {
      const graph::ScopedTimer timer(own.graph_building_s);
      next = build_graph(problem, init, options_.graph, GraphForm::kBatch, between);
      if (options_.formulation == Formulation::kDynamicFactorGraph) {
        dfg_steps = use_dfg_dynamics(next, problem, options_.graph, options_.dfg);
      }
    } catch (const std::exception& e) {
      Plan p = failed_plan(method, PlanStatus::kInvalidProblem, e.what());
      return p;
    }
    if (round > 0) {
      next.values = pg.values;  // the same variables: interval rows add none
      resize_interval_records(state, next, 2 * unactuated_count(problem));
    }
    pg = std::move(next);
    OuterLoopOptions loop = dfg_steps.empty() ? options_.outer_loop : outer_loop_options(options_);
    // Limit rows added to a converged solve that it already keeps change nothing: the solve was
    // the optimum of a relaxation of this graph, and it is feasible here, so it is this one's.
    // A converged warm-up that already holds the interpolant's rows is kept too: its objective
    // is that of a graph differing only in the RK4 step, and every row of this one holds.
    if (after_converged) {
      const auto t_check = std::chrono::steady_clock::now();
      const ConstraintReport worst = worst_constraint(pg.constraints(false), pg.values);
      own.between_knot_checks_s += graph::seconds_since(t_check);
      if (worst.scaled_violation <= loop.constraint_tolerance) {
        // The new rows' multipliers start at zero, as a solve would start them.
        for (const FactorEntry* e : pg.constraints(false)) state.bind(*e);
        r.worst = worst;
        spdlog::debug("{}: interval round {}: the last solve holds its rows (worst {:.3g}); not "
                      "re-solved", problem.name, round, worst.scaled_violation);
        break;
      }
    }
    loop.max_total_iterations -= r.iterations;  // one budget for all rounds
    AugmentedLagrangian al(pg.constraints(false), state, options_.augmented_lagrangian);
    // A re-solve starts feasible but for the rows just added: at the largest penalty it is a
    // projection onto them (the multipliers carry the objective's balance), where a smaller one
    // lets LM trade feasibility for the objective first and spend many more linearizations.
    // It also starts at the final inner tolerance: a looser first LM solve would be followed
    // by one more at the final tolerance, a relinearization that moves almost nothing.
    if (round > 0 || from_interpolant) {
      state.set_penalty(options_.augmented_lagrangian.max_penalty);
      loop.inner_tolerance_initial = loop.inner_tolerance_final;
    }
    const OuterLoopResult stage = solve_outer_loop(pg.graph, pg.values, al, loop, problem.name);
    const int before = r.iterations, before_outer = r.outer_iterations,
              before_solves = r.linear_solves;
    const SolveTimes before_times = r.times;
    r = stage;
    r.iterations += before;
    r.outer_iterations += before_outer;
    r.linear_solves += before_solves;
    r.times += before_times;
    spdlog::debug(
        "{}: interval round {}{}: {} LM iterations, {}; {} of {} intervals with limit points",
        problem.name, round, between.integration_step != kMaxIntegrationStep ? " (warm-up)" : "",
        stage.iterations, to_string(stage.status),
        std::count_if(between.limits.begin(), between.limits.end(), [](char c) { return c != 0; }),
        problem.steps);
    // A knot-only solve that stalled far from feasible ends the attempt: the rows between the
    // knots only add constraints.
    if (between.knots_only && r.status == PlanStatus::kInfeasible &&
        options_.abandon_violation > 0 && r.worst.scaled_violation > options_.abandon_violation) {
      spdlog::debug("{}: the knot-only solve ended infeasible (worst {:.3g} at {}); attempt "
                    "abandoned", problem.name, r.worst.scaled_violation, r.worst.where);
      break;
    }
    // A warm-up's graph is never the answer: the rows on the interpolant follow it, even with
    // no iterations left.
    const bool on_interpolant = between.integration_step == kMaxIntegrationStep;
    if (r.status == PlanStatus::kNonFinite ||
        (on_interpolant && (round == kMaxIntervalRounds ||
                            r.iterations >= options_.outer_loop.max_total_iterations))) {
      break;
    }
    const auto t_check = std::chrono::steady_clock::now();
    const bool added = add_flags(
        between.limits,
        intervals_near_limits(problem, plan_from_values(problem, pg.values, options_.dfg.keys),
                              kNearLimit));
    own.between_knot_checks_s += graph::seconds_since(t_check);
    if (between.knots_only && shooting) {
      between.knots_only = false;
      if (warmup) between.integration_step = warmup_step;
      continue;
    }
    if (!on_interpolant) {
      between.integration_step = kMaxIntegrationStep;
      after_converged = r.status == PlanStatus::kConverged;
      continue;
    }
    if (!added) break;
    between.knots_only = false;
    after_converged = r.status == PlanStatus::kConverged;
  }
  if (r.status == PlanStatus::kInfeasible) r.reason = infeasible_reason(problem, r);

  Plan plan = solved_plan(problem, pg, r, method, options_);
  plan.stats.times += own;
  plan.stats.solve_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (solution != nullptr) {
    solution->graph = std::move(pg);
    solution->constraints = std::move(state);
  }
  return plan;
}

Plan BatchPlanner::solve_by_effort_continuation(const Problem& problem,
                                                const Eigen::VectorXd& q_goal,
                                                const std::string& method,
                                                BatchSolution* solution) const {
  std::optional<Plan> last;  // the last stage that validated
  SolveStats stages;
  for (double scale : options_.effort_continuation) {
    const Problem stage = with_effort_scaled(problem, scale);
    Plan p = solve(stage, last ? warm_start(stage, *last) : straight_line(stage, q_goal), method);
    spdlog::debug("plan {}: effort x{}: {}", problem.name, scale,
                  p.success() ? std::string("valid") : to_string(p.stats.status));
    add_work(stages, p.stats);
    if (p.success()) last = std::move(p);
  }
  Plan plan = solve(problem, last ? warm_start(problem, *last) : straight_line(problem, q_goal),
                    method, solution);
  add_work(plan.stats, stages);
  return plan;
}

std::optional<Plan> BatchPlanner::solve_refined(const Problem& problem, int coarse_steps,
                                                const std::string& method, SolveStats& coarse_stats,
                                                BatchSolution* solution) const {
  Problem coarse = problem;
  coarse.steps = coarse_steps;
  const Plan c = plan(coarse);
  add_counts(coarse_stats, c.stats);
  spdlog::debug("plan {}: refinement from {} steps: coarse plan {}", problem.name, coarse_steps,
                c.success() ? std::string("valid") : to_string(c.stats.status));
  if (!c.success()) return std::nullopt;
  return solve(problem, refined_start(problem, c), method, solution, true);
}

}  // namespace kinograph::planning

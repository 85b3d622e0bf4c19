#include "kinograph/planning/replanner.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstring>
#include <map>
#include <set>

namespace kinograph::planning {
namespace {

// The answer's path from a batch planner's method: "batch-L" → "batch", "batch-W" →
// "warm-start".
std::string path_of(std::string method) {
  for (auto [from, to] : {std::pair{"batch-L", "batch"}, std::pair{"batch-W", "warm-start"}}) {
    if (method.rfind(from, 0) == 0) method.replace(0, std::strlen(from), to);
  }
  return method;
}

// Largest joint change between two joint goals; infinity when either is not a joint goal.
double joint_goal_change(const Goal& a, const Goal& b) {
  if (a.kind != Goal::Kind::kJoint || b.kind != Goal::Kind::kJoint || a.q.size() != b.q.size() ||
      a.q.size() == 0) {
    return std::numeric_limits<double>::infinity();
  }
  return (a.q - b.q).cwiseAbs().maxCoeff();
}

// The change from `from` to `to`: obstacles by id, the goal when `new_goal`, the start and the
// horizon when they differ. Obstacles that move along a trajectory are kept as they are unless
// they were added or removed.
ProblemChange change_between(const Problem& from, const Problem& to, bool new_goal) {
  ProblemChange change;
  std::map<int, const collision::Obstacle*> planned;
  for (const auto& o : from.obstacles) planned[o.id] = &o;
  for (const auto& o : to.obstacles) {
    const auto it = planned.find(o.id);
    const bool moving = it != planned.end() && it->second->is_moving() && o.is_moving();
    if (it == planned.end() || (!moving && !collision::same_static_obstacle(*it->second, o))) {
      change.add_or_move.push_back(o);
    }
    if (it != planned.end()) planned.erase(it);
  }
  for (const auto& [id, o] : planned) change.remove.push_back(id);
  if (new_goal) change.goal = to.goal;
  if (to.start_q != from.start_q || to.start_qd != from.start_qd) {
    change.start_q = to.start_q;
    change.start_qd = to.start_qd;
  }
  if (to.horizon != from.horizon) change.horizon = to.horizon;
  return change;
}

}  // namespace

Replanner::Replanner(ReplannerOptions options)
    : options_(std::move(options)),
      batch_(options_.incremental.batch),
      incremental_(options_.incremental) {}

Plan Replanner::plan(const Problem& problem, bool new_goal, const Plan* warm, int warm_knots) {
  report_ = ReplanReport();
  // A warm start must fit the problem's knots.
  if (warm && warm->q.rows() != problem.steps + 1) warm = nullptr;
  try {
    Plan p = options_.use_incremental ? incremental_path(problem, new_goal, warm, warm_knots)
                                      : batch_path(problem, new_goal, warm);
    if (p.success()) {
      last_valid_ = p;
      last_problem_ = problem;
    }
    return p;
  } catch (...) {
    ready_ = false;
    throw;
  }
}

Plan Replanner::replan(const ProblemChange& change) {
  if (!incremental_.has_plan() && !last_valid_) {
    report_ = ReplanReport();
    return failed_plan("incremental", PlanStatus::kNoPlan, "replan needs a plan first");
  }
  const Problem& current = incremental_.has_plan() ? incremental_.problem() : last_problem_;
  Problem next;
  std::set<int> changed;
  if (const std::string error = apply_change(current, change, next, changed); !error.empty()) {
    report_ = ReplanReport();
    return failed_plan("incremental", PlanStatus::kInvalidProblem, error);
  }
  return plan(next, change.goal.has_value());
}

Plan Replanner::batch_path(const Problem& problem, bool new_goal, const Plan* given) {
  // An obstacle or start change keeps the goal: the previous plan is the natural start.
  const bool warm =
      given || (!new_goal && last_valid_ && last_valid_->q.rows() == problem.steps + 1);
  Plan plan = batch_.plan(problem, given ? given : warm ? &*last_valid_ : nullptr);
  // A warm start can be trapped on the wrong side of a new obstacle.
  if (warm && !plan.success()) {
    spdlog::info("warm-started replan did not validate ({}); planning from scratch",
                 plan.stats.reason);
    const double warm_time = plan.stats.solve_time_s;
    report_.retried_from_scratch = true;
    plan = batch_.plan(problem);
    plan.stats.solve_time_s += warm_time;
    plan.stats.method += " after warm-start";
  }
  report_.method = path_of(plan.stats.method);
  return plan;
}

Plan Replanner::from_scratch(const Problem& problem) {
  // IncrementalPlanner::plan answers with the batch plan whenever that validates, so a failed
  // first plan is not retried by the batch planner (it would solve the same problem again).
  Plan plan = incremental_.plan(problem);
  ready_ = plan.success();
  report_.method = path_of(plan.stats.method);
  return plan;
}

Plan Replanner::incremental_path(const Problem& problem, bool new_goal, const Plan* warm,
                                 int warm_knots) {
  bool scratch = !ready_ || !incremental_.has_plan() ||
                 incremental_.problem().steps != problem.steps;
  if (!scratch && new_goal) {
    const double change = joint_goal_change(incremental_.problem().goal, problem.goal);
    if (std::isfinite(change) && change > options_.max_incremental_goal_change) {
      spdlog::info("goal moved by {:.2f} rad (> {:.2f}): planning from scratch", change,
                   options_.max_incremental_goal_change);
      scratch = true;
    }
  }
  if (scratch) return from_scratch(problem);

  const Plan previous = incremental_.current_plan();
  if (warm && warm_knots > 0 && !new_goal) {
    const std::string refusal = incremental_.shift_refusal(problem, warm_knots);
    // The warm start, not the plan before the shift, fits the shifted problem's knots.
    if (refusal.empty()) {
      return answer_incremental(problem, incremental_.shift(problem, warm_knots), *warm,
                                warm_knots);
    }
    spdlog::debug("replan not shifted by {} knots: {}", warm_knots, refusal);
  }
  if (warm) {
    // The given trajectory, not the current plan, is where the solve starts.
    Plan plan = incremental_.plan(problem, warm);
    report_.method = "warm-start";
    ready_ = plan.success();
    // A problem refused before solving (e.g. a start in collision) leaves nothing to recover.
    if (plan.success() || plan.stats.status == PlanStatus::kInvalidProblem) return plan;
    return recover(problem, std::move(plan), previous);
  }
  return answer_incremental(
      problem, incremental_.replan(change_between(incremental_.problem(), problem, new_goal)),
      previous, 0);
}

Plan Replanner::answer_incremental(const Problem& problem, Plan plan, const Plan& previous,
                                   int knots) {
  report_.statistics = incremental_.last_stats();
  report_.method = "incremental";
  const bool refused = plan.stats.status == PlanStatus::kInvalidProblem;
  // A refused change left the planner as it was: it can still replan. Any other failure leaves
  // it at a trajectory that did not validate, a poor start for the next change.
  ready_ = plan.success() || (refused && ready_);
  if (refused) return plan;
  report_.incremental = true;
  const IncrementalStats& st = report_.statistics;
  spdlog::info(
      "iDFGP: {}{} ISAM2 updates, {} multiplier rounds, {} variables re-eliminated, factors {} "
      "replaced + {} added, {:.1f} ms incremental",
      knots > 0 ? "shifted " + std::to_string(knots) + " knots, " : std::string(), st.updates,
      st.rounds, st.variables_reeliminated, st.factors_replaced, st.factors_added,
      st.incremental_time_s * 1e3);
  if (plan.success()) return plan;
  return recover(problem, std::move(plan), previous);
}

Plan Replanner::recover(const Problem& problem, Plan failed, const Plan& previous) {
  Plan plan = std::move(failed);
  if (options_.fallback) {
    report_.fell_back = true;
    report_.fallback_reason =
        plan.validation.failures.empty() ? to_string(plan.stats.status)
                                     : plan.validation.failures.front();
    spdlog::info("incremental replan did not validate ({}); falling back to a batch solve",
                 report_.fallback_reason);
    const double spent = plan.stats.solve_time_s;
    plan = incremental_.plan(incremental_.problem(), &previous);
    plan.stats.reason = "incremental replan did not validate (" + report_.fallback_reason +
                        "); warm-started batch solve" +
                        (plan.stats.reason.empty() ? "" : ": " + plan.stats.reason);
    plan.stats.solve_time_s += spent;
    report_.method = "batch after incremental";
    ready_ = plan.success();
  }
  // The warm start can be on the wrong side of a far goal or an obstacle across the path; a
  // solve from scratch (straight line and detours) is the last resort.
  if (!plan.success() && options_.retry_from_scratch) {
    spdlog::info("replan did not validate ({}); planning from scratch", plan.stats.reason);
    const double spent = plan.stats.solve_time_s;
    report_.retried_from_scratch = true;
    plan = from_scratch(problem);
    plan.stats.solve_time_s += spent;
    report_.method = "batch after incremental";
  }
  return plan;
}

}  // namespace kinograph::planning

#pragma once
// The replanning policy of a robot's planner: which plans are incremental replans (iDFGP),
// which are batch solves, and what answers when a plan does not validate. The first request,
// and any request after a plan that failed, is planned from scratch; later ones are applied as
// a ProblemChange to the current plan. An incremental result that does not validate is redone
// by a batch solve warm-started from the previous plan, and then from scratch.
#include <limits>
#include <optional>
#include <string>

#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/incremental/incremental_planner.h"

namespace kinograph::planning {

/// Options of Replanner.
struct ReplannerOptions {
  /// The incremental planner; its `batch` options serve every batch solve too.
  IncrementalPlannerOptions incremental;
  /// Replan incrementally after the first plan; false: every plan is a batch solve,
  /// warm-started from the current plan when only obstacles or the start changed.
  bool use_incremental = true;
  /// An incremental result that does not validate is redone by a warm-started batch solve.
  bool fallback = true;
  /// A replan that still does not validate is planned once more from scratch.
  bool retry_from_scratch = true;
  /// A new joint goal farther than this from the current one (largest joint change, rad) is
  /// planned from scratch; pose goals always replan incrementally.
  double max_incremental_goal_change = std::numeric_limits<double>::infinity();
};

/// How the last answer came about.
struct ReplanReport {
  /// The path that answered: "batch", "warm-start", "batch after warm-start", "incremental" or
  /// "batch after incremental".
  std::string method;
  bool incremental = false;  ///< an incremental replan ran (validated or not, not refused)
  bool fell_back = false;    ///< its result did not validate and a batch solve answered
  /// The warm-started solve (the fallback, or a batch replan's warm start) did not validate
  /// either, and a plan from scratch was made (retry_from_scratch).
  bool retried_from_scratch = false;
  std::string fallback_reason;   ///< the incremental result's first validation failure
  IncrementalStats statistics;   ///< of the incremental replan
};

/// The planner of one robot: an IncrementalPlanner and a BatchPlanner under the policy above.
/// Single-threaded.
class Replanner {
 public:
  explicit Replanner(ReplannerOptions options = {});

  /// Plans `problem`: `new_goal` marks a new request (else the current goal's problem changed,
  /// e.g. obstacles or the start). The answer's path is in last_report(). `warm`, when given, is
  /// a better initial trajectory for a replan than the current plan, e.g. that plan continued in
  /// time when the start moved along it: the replan is then a solve warm-started from it on the
  /// incremental graph (method "warm-start"), with the usual fallbacks. `warm_knots` > 0 says
  /// that `warm` is the current plan gone on by that many knots: the replan then shifts the
  /// Bayes tree instead (IncrementalPlanner::shift, method "incremental") when the shift applies.
  Plan plan(const Problem& problem, bool new_goal, const Plan* warm = nullptr,
            int warm_knots = 0);
  /// Applies `change` to the current problem and plans it (a new request when it has a goal).
  /// Needs a first plan (else status "no_plan").
  Plan replan(const ProblemChange& change);
  /// Readies the incremental planner for the next change (IncrementalPlanner::prepare) when
  /// the next request would replan incrementally; call while idle. Returns its wall time [s].
  double prepare() { return ready_ && options_.use_incremental ? incremental_.prepare() : 0; }
  /// Forgets the current plan (the next request is planned from scratch), e.g. after an error.
  void reset() { ready_ = false; }

  const ReplanReport& last_report() const { return report_; }
  const IncrementalPlanner& incremental() const { return incremental_; }
  const ReplannerOptions& options() const { return options_; }

 private:
  Plan batch_path(const Problem& problem, bool new_goal, const Plan* warm);
  Plan from_scratch(const Problem& problem);
  Plan incremental_path(const Problem& problem, bool new_goal, const Plan* warm, int warm_knots);
  /// The answer of an incremental replan (on the tree shifted by `knots`, if > 0): its report,
  /// and recover() from `previous` when it does not validate.
  Plan answer_incremental(const Problem& problem, Plan plan, const Plan& previous, int knots);
  /// The warm-started batch solve (then the plan from scratch) after a failed replan.
  Plan recover(const Problem& problem, Plan failed, const Plan& previous);

  ReplannerOptions options_;
  BatchPlanner batch_;
  IncrementalPlanner incremental_;
  bool ready_ = false;  // the incremental planner's plan validated (or a refusal kept it)
  std::optional<Plan> last_valid_;
  Problem last_problem_;  // the problem of last_valid_
  ReplanReport report_;
};

}  // namespace kinograph::planning

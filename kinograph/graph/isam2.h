#pragma once
// Incremental smoothing and mapping (ISAM2, Kaess et al., IJRR 2012) on the kinograph engine:
// the iDFGP solver. A Bayes tree holds the factorized linearized problem; each update re-
// eliminates only the cliques touched by new, removed or relinearized factors and their
// ancestors, reattaching the untouched subtrees through their cached marginal factors.
#include <Eigen/Core>
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "kinograph/graph/banded_system.h"
#include "kinograph/graph/bayes_tree.h"
#include "kinograph/graph/factor_graph.h"
#include "kinograph/graph/share_out_choice.h"
#include "kinograph/graph/values.h"
#include "kinograph/graph/worker_pool.h"

namespace kinograph::graph {

/// How each update turns the linear solution into a new estimate.
enum class ISAM2Step {
  kGaussNewton,  ///< δ from the Bayes tree (LM-damped on the re-eliminated part if unsafe)
  /// Powell's dogleg between the Gauss–Newton and steepest-descent steps of the whole tree,
  /// with a trust region that shrinks and retries within the update while the error rises; a
  /// radius-limited step relinearizes every moved variable at the next update (GTSAM's ISAM2
  /// Dogleg stalls there). Costs a pass over the whole tree and all factors per trial.
  kDogleg,
};

/// Options of ISAM2 (fixed for its lifetime). Defaults suit planning problems in SI units.
struct ISAM2Options {
  /// A variable is relinearized when max|δ_j| over its components exceeds this (units of the
  /// variable; GTSAM's default). Larger: fewer relinearizations, an estimate further from a
  /// Gauss–Newton iterate.
  double relinearize_threshold = 0.1;
  /// Check relinearization only every k-th update (1 = every update), to save the
  /// re-elimination it causes when updates come faster than the estimate moves.
  int relinearize_skip = 1;
  /// Back-substitution stops descending where a variable changes by less than this (max-abs,
  /// units of the variable); 0 gives the exact solution, larger visits fewer cliques.
  double wildfire_threshold = 1e-7;
  /// Re-eliminate everything when the affected top holds more than this fraction of the free
  /// variables (cheaper than detaching and reattaching most of the tree).
  double full_reelimination_fraction = 0.6;
  /// Order the variables touched by changed factors last (near the root, so the next change to
  /// them re-eliminates little) only while they are at most this fraction of the variables
  /// re-eliminated: forcing most of a chain last makes the rest go first and fill one giant
  /// clique. Explicit constrained_last keys are always honoured.
  double constrain_touched_fraction = 0.3;
  /// How the linear solution becomes a new estimate (see ISAM2Step).
  ISAM2Step step = ISAM2Step::kGaussNewton;
  /// A Gauss–Newton update that relinearizes more than full_reelimination_fraction of the
  /// variables solves the whole system with a banded Cholesky in slot order (BandedSystem)
  /// when its Hessian is a band there, as a trajectory's is, instead of rebuilding the Bayes
  /// tree: the same step up to rounding, at a fraction of the cost. The tree is rebuilt by the
  /// next update that changes only part of the graph or by relinearize_at_estimate(); until
  /// then bayes_tree() is empty. Off: the tree is always current.
  bool banded_full_updates = true;

  /// While the safeguard (or Dogleg) evaluates the error at a new estimate, also linearize
  /// there, so a variable relinearized at that estimate reuses it instead of evaluating its
  /// factors again. Pays off where Jacobians cost little beside the residuals; a rejected step
  /// wastes them. Changes the work only, never the iterates.
  bool linearize_at_evaluation = true;
  /// Keep a linear factor's JᵀJ between linearizations while its Jacobian is unchanged
  /// (Factor::jacobian_version), forming only Jᵀr again. Changes the work only, never the
  /// iterates.
  bool reuse_constant_jacobians = true;
  /// Threads that linearize and evaluate the factors of an update when there are many (the
  /// caller's and the process's pool, as LevenbergMarquardtOptions::threads); the factors
  /// that are not Factor::parallel_safe stay on the caller's. Changes the work only, never
  /// the iterates.
  int threads = 2;

  /// Gauss–Newton only (Dogleg always evaluates the error): evaluate the nonlinear error after
  /// each update (incrementally: only factors on variables that moved) and, if it rose,
  /// re-eliminate the affected top with Marquardt damping λ·diag(H) until it no longer rises.
  /// A damped step is taken in full: its variables are relinearized at the next update whatever
  /// the threshold, so progress never stalls below it. Off: the error is not evaluated.
  bool safeguard = true;
  // The safeguard's λ (dimensionless: it scales diag(H)), carried from update to update.
  /// First λ after a rejected undamped trial.
  double lambda_initial = 1e-2;
  /// λ grows by this factor after each further rejected trial (> 1).
  double lambda_factor = 10;
  /// λ shrinks by this factor after an accepted update (≥ 1): lingering damping suppresses the
  /// smooth, low-curvature modes of a chain, dropping it at once can overshoot.
  double lambda_decrease = 10;
  /// Below this the carried λ drops to 0 (plain Gauss–Newton again).
  double lambda_min = 1e-7;
  /// Give up (keep the last trial, flag error_increased) when λ would exceed this.
  double lambda_max = 1e12;
  /// Floor of diag(H) in the damping (units of H), so a direction of no curvature is damped.
  double min_diagonal = 1e-6;
  /// Rise of the error, relative to error_before, that still counts as no rise (rounding,
  /// wildfire approximation); for the safeguard and Dogleg alike.
  double error_rise_tolerance = 1e-9;

  /// Dogleg: initial trust radius on ‖δ‖₂ (units of the stacked variables).
  double trust_radius_initial = 1.0;
  /// Dogleg: floor of the trust radius; an update gives up (flags the increase) below it.
  double trust_radius_min = 1e-12;
  /// Dogleg: most steps tried within one update before giving up (flags the increase).
  int max_dogleg_trials = 40;
};

/// Per-call options of ISAM2::update().
struct ISAM2UpdateOptions {
  /// Variables to eliminate last (near the root) besides those touched by changed factors, e.g.
  /// the final step of a trajectory whose goal will change.
  std::vector<Key> constrained_last;
  /// Relinearize every variable with a non-zero δ, regardless of the threshold.
  bool force_relinearize = false;
};

/// Outcome of one update.
enum class ISAM2Status {
  kOk,         ///< estimate computed (see error_increased for the safeguard's verdict)
  kSingular,   ///< a clique's information block is not positive definite (reason names it)
  kNonFinite,  ///< a factor returned NaN/Inf (reason names it)
};

/// "ok", "singular", "non_finite".
std::string to_string(ISAM2Status status);

/// What an update did and what it cost.
struct ISAM2Result {
  ISAM2Status status = ISAM2Status::kOk;   ///< whether an estimate was computed
  std::string reason;                      ///< what went wrong (empty when ok)
  std::vector<size_t> new_factor_indices;  ///< index of each added factor, for later removal
  /// True when the returned estimate's error exceeds error_before: the safeguard reached
  /// lambda_max, or Dogleg its radius floor or trial limit. Set only when error_evaluated.
  bool error_increased = false;
  double error_before = 0;        ///< new graph's error at the previous estimate (if evaluated)
  double error_after = 0;         ///< error at the new estimate (if evaluated)
  bool error_evaluated = false;   ///< error_before/after hold the error (safeguard or Dogleg)
  bool full_reelimination = false;  ///< the whole tree was rebuilt (not only the affected top)
  int variables_reeliminated = 0;   ///< variables of the re-eliminated part of the tree
  int cliques_reeliminated = 0;     ///< cliques built by this update
  int variables_relinearized = 0;   ///< variables whose linearization point moved
  int factors_linearized = 0;  ///< new factors plus those touching relinearized variables
  int factors_reused = 0;      ///< of those, linearizations kept from the error evaluation
  int factors_zero = 0;        ///< of those, factors without an active row (they add nothing)
  int jacobians_kept = 0;      ///< evaluations of linear factors that kept JᵀJ (all trials)
  int cliques_solved = 0;      ///< cliques back-substituted (last trial)
  /// Numeric eliminations (Gauss–Newton); with Dogleg, one plus the dogleg steps tried.
  int trials = 0;
  double lambda = 0;           ///< λ of the GN trial taken (the carried λ if nothing changed)
  double trust_radius = 0;     ///< Dogleg's trust radius after the update
  double linearize_s = 0;      ///< wall time choosing the affected top and linearizing [s]
  double eliminate_s = 0;      ///< wall time ordering, symbolic and numeric elimination [s]
  double solve_s = 0;          ///< wall time back-substituting and evaluating the error [s]
  double total_s = 0;          ///< wall time of the whole update [s]

  bool ok() const { return status == ISAM2Status::kOk; }
};

/// Incremental nonlinear least squares on a growing/changing factor graph. Factors are added
/// and removed by index (indices are stable, as in FactorGraph); variables are added with their
/// initial values and never removed. Fixed variables (Values::set_fixed in new_values) stay
/// constant.
class ISAM2 {
 public:
  explicit ISAM2(ISAM2Options options = {});

  /// Adds `new_factors` (their variables must be known or in `new_values`), removes the factors
  /// with the given indices, relinearizes, re-eliminates the affected top of the Bayes tree and
  /// back-substitutes. Removing a factor and adding its replacement in one call is the goal-
  /// change pattern. Throws std::invalid_argument / std::out_of_range for inconsistent input
  /// (unknown key, duplicate variable, bad index), before changing any state; numerical trouble
  /// comes back in the result (then the next update re-eliminates everything).
  ISAM2Result update(const std::vector<FactorPtr>& new_factors = {},
                     const std::vector<size_t>& removed_factor_indices = {},
                     const Values& new_values = {}, const ISAM2UpdateOptions& options = {});

  /// Moves the linearization point to the estimate (θ ← θ + δ, δ ← 0) for every variable that
  /// moved, relinearizes their factors and re-eliminates the tree there (damped with the
  /// carried λ), with `last` ordered near the root. The estimate stays as it is. It is the work
  /// a forced update does first, done ahead (e.g. while a planner waits for the next change):
  /// the next update re-eliminates only what its own changes touch and takes the forced
  /// update's step (the whole tree is re-eliminated if that step raises the error). A failure
  /// comes back in the result, as in update(); the next update then rebuilds everything.
  ISAM2Result relinearize_at_estimate(const std::vector<Key>& last = {});

  /// Renames every variable, in θ, the estimate and every factor at once (`rename` must keep
  /// distinct keys distinct): the Bayes tree, the linearizations and the estimate stay as they
  /// are, so a graph whose variables are renamed (e.g. a trajectory's steps counted from a later
  /// start) is updated incrementally. Throws std::invalid_argument when two keys would merge,
  /// before anything changes.
  void rename_variables(const std::function<Key(Key)>& rename);

  /// Current estimate θ + δ.
  const Values& estimate() const { return estimate_; }
  /// Linearization point θ.
  const Values& linearization_point() const { return theta_; }
  /// The factors (removed slots empty).
  const FactorGraph& graph() const { return graph_; }
  const BayesTree& bayes_tree() const { return tree_; }
  const ISAM2Options& options() const { return options_; }
  /// Nonlinear error ½Σ‖r‖² at the estimate (evaluates every factor).
  double error() const { return graph_.error(estimate_); }

  /// Checks the Bayes tree's invariants against the current graph (every free variable frontal
  /// once, every active factor with a free variable in exactly one clique, separators ⊆
  /// parents' variables). Empty string when they hold.
  std::string check_invariants() const;

 private:
  struct UpdateWork;  // what one update() works on, passed from step to step

  // Steps of update(), in order (isam2.cc).
  void validate_update(const std::vector<FactorPtr>& new_factors,
                       const std::vector<size_t>& removed_factor_indices,
                       const Values& new_values) const;
  void add_variables(const Values& new_values);
  void remove_factors(const std::vector<size_t>& removed_factor_indices, UpdateWork& work);
  void add_factors(const std::vector<FactorPtr>& new_factors, UpdateWork& work,
                   ISAM2Result& result);
  std::vector<int> variables_to_relinearize(const ISAM2UpdateOptions& options) const;
  bool linearize_new_factors(UpdateWork& work, ISAM2Result& result);
  void park_new_factors(UpdateWork& work);
  void relinearize(const ISAM2UpdateOptions& options, UpdateWork& work, ISAM2Result& result);
  void report_unchanged(const UpdateWork& work, ISAM2Result& result) const;
  void find_affected_top(UpdateWork& work);
  bool linearize_factors(const std::vector<int>& factors, ISAM2Result& result);
  std::vector<int> factors_to_eliminate(const UpdateWork& work) const;
  void build_affected_top(const ISAM2UpdateOptions& options, UpdateWork& work,
                          ISAM2Result& result);
  bool detach_and_linearize(UpdateWork& work, ISAM2Result& result, bool allow_banded);
  bool solve_banded(const UpdateWork& work, int relinearized);
  bool eliminate_and_solve(UpdateWork& work, ISAM2Result& result);
  bool factorize_and_solve(UpdateWork& work, const Eigen::VectorXd* damping,
                           ISAM2Result& result);
  void carry_damping(const UpdateWork& work, ISAM2Result& result);
  void reeliminate_all(UpdateWork& work, ISAM2Result& result);
  void apply_dogleg(ISAM2Result& result);

  // Helpers of the steps.
  void mark(int slot, UpdateWork& work);
  void fail(ISAM2Result& result, ISAM2Status status, std::string reason);
  void fail_singular(ISAM2Result& result, int slot);
  std::vector<int> active_factors() const;
  std::vector<std::vector<int>> elimination_incidence(const UpdateWork& work,
                                                      const std::vector<int>& local) const;
  std::vector<int> ordering_groups(const ISAM2UpdateOptions& options, const UpdateWork& work,
                                   const std::vector<int>& local) const;
  Eigen::VectorXd damping_diagonal(const std::vector<int>& vars) const;
  Eigen::VectorXd cauchy_point() const;

  // Linearizing one factor, and the error at the estimate, with one worker's scratch.
  struct FactorScratch {
    Eigen::VectorXd r;
    Eigen::MatrixXd J;
    RowSupport support;
    std::vector<const double*> ptrs;
    std::vector<int> free_vars, free_offsets, free_cols;
    int reused = 0;          // linearizations taken from at_estimate_, not yet counted
    int jacobians_kept = 0;  // kept linear factors' JᵀJ, not yet counted
  };
  /// Error of factor f at `at` and, with `out`, its linearization there (false when the
  /// residual or Jacobian is not finite).
  bool evaluate_factor(int f, const Values& at, LinearizedFactor* out, double* error,
                       FactorScratch& w);
  std::string non_finite_reason(int f) const;
  void collect_free_columns(const Factor& factor, const std::vector<int>& slots, const Values& at,
                            FactorScratch& w);
  bool relinearize_kept_jacobian(const Factor& factor, LinearizedFactor& lf, double* error,
                                 FactorScratch& w);
  bool linearize_fresh(const Factor& factor, LinearizedFactor& lf, double* error,
                       FactorScratch& w);
  void form_normal_equations(Eigen::Ref<Eigen::MatrixXd> J, int active, LinearizedFactor& lf,
                             const FactorScratch& w);
  bool linearize_factor(int f, FactorScratch& w);
  double factor_error_at_estimate(int f, FactorScratch& w);
  /// Calls one(f, scratch) for every factor index of `factors`, on options_.threads workers
  /// when they are many and `choice` finds sharing pays, and counts what the scratches noted.
  template <class F>
  void for_each_factor(const std::vector<int>& factors, ShareOutChoice& choice, F&& one);
  void count_scratch();
  void refresh_estimate(const std::vector<int>& changed_vars);
  void sync_layout();
  double total_error() const;

  ISAM2Options options_;
  FactorGraph graph_;
  Values theta_;
  Values estimate_;
  Eigen::VectorXd delta_;     // applied step (θ + delta_ = estimate)
  Eigen::VectorXd delta_gn_;  // linear solution, tree or banded (delta_ with Gauss–Newton)
  BayesTree tree_;
  std::vector<int> slot_dims_, slot_offsets_;  // per slot, in θ's layout
  BandedSystem banded_;  // the whole system, for banded_full_updates
  bool tree_deferred_ = false;  // the last update was banded: the tree waits to be rebuilt
  std::vector<LinearizedFactor> linearized_;    // per factor index
  std::vector<LinearizedFactor> at_estimate_;   // per factor: linearized at the estimate
  std::vector<char> at_estimate_ok_;            // per factor: at_estimate_ is current
  int factors_reused_ = 0;                      // linearizations taken from at_estimate_
  int jacobians_kept_ = 0;                      // evaluations that kept a linear factor's JᵀJ
  std::vector<std::vector<int>> factor_slots_;  // per factor: Values slot per key
  std::vector<double> factor_error_;            // per factor: error at the estimate
  std::vector<std::vector<int>> var_factors_;   // per slot: factor indices touching it
  std::vector<int> damped_vars_;                // eliminated with damping last time
  bool prepared_ = false;  // relinearize_at_estimate built the tree; no update since
  std::vector<int> prepared_damped_;  // eliminated damped by relinearize_at_estimate
  std::vector<int> stamp_;                      // per slot scratch
  int stamp_counter_ = 0;
  std::vector<int> factor_stamp_;
  int factor_stamp_counter_ = 0;
  double lambda_ = 0;
  double trust_radius_;
  bool last_step_limited_ = false;
  bool needs_full_ = true;
  int update_count_ = 0;
  // Workspaces for linearizing factors: one per worker, and the lists shared out.
  std::array<FactorScratch, kMaxWorkers> scratch_;
  std::vector<int> any_worker_, caller_only_, refreshed_;
  ShareOutChoice linearize_choice_, refresh_choice_;
  std::vector<char> linearized_ok_;  // per factor: its last linearize_factors succeeded
};

}  // namespace kinograph::graph

#pragma once
// The Bayes tree of ISAM2 (Kaess et al., IJRR 2012): the square-root information matrix of a
// linearized factor graph, grouped into cliques of frontal variables with a dense conditional
// R_F x_F + R_S x_S = d on the clique's separator. Elimination works on the information form
// (Cholesky of the gathered JᵀJ blocks per clique, i.e. multifrontal Cholesky), which is
// cheaper than per-clique QR and gives the same R up to row signs.
#include <Eigen/Core>
#include <string>
#include <vector>

namespace kinograph::graph {

/// One factor linearized at the linearization point, in information form: ½‖J δ + r‖² =
/// ½ δᵀHδ + gᵀδ + error. Only free (non-fixed) variables have blocks.
struct LinearizedFactor {
  std::vector<int> vars;     ///< free variable slots (Values slots) touched by the factor
  std::vector<int> offsets;  ///< first row/column of each variable's block in H and g
  Eigen::MatrixXd H;         ///< JᵀJ over the free variables (symmetric)
  Eigen::VectorXd g;         ///< Jᵀr
  double error = 0;          ///< ½‖r‖² at the linearization point
  bool active = false;       ///< false for removed factors (slot kept empty)
  /// No row of the factor is active (e.g. an inequality that holds): H and g are zero and not
  /// formed, and the factor adds nothing to its clique.
  bool zero = false;
  /// The factor's Factor::jacobian_version when H was formed, and for a linear factor its
  /// whitened Jacobian over the free variables (H and J are kept while the version holds).
  long jacobian_version = -1;
  Eigen::MatrixXd J;
};

/// A clique: frontal variables eliminated together, conditioned on the separator (variables of
/// the parent clique). Holds the conditional [R_FF R_FS], d and the cached marginal (Schur
/// complement) factor on the separator that lets ISAM2 reattach the clique as an orphan.
struct Clique {
  std::vector<int> frontals;   ///< variable slots, in elimination order
  std::vector<int> separator;  ///< variable slots, in elimination order
  int frontal_dim = 0;
  int separator_dim = 0;
  int parent = -1;             ///< clique id, −1 for a root
  std::vector<int> children;   ///< clique ids
  std::vector<int> factors;    ///< factor indices eliminated in this clique
  Eigen::MatrixXd R;           ///< [R_FF R_FS]: frontal_dim × (frontal_dim + separator_dim)
  Eigen::VectorXd d;           ///< right-hand side of the conditional
  Eigen::MatrixXd marginal_H;  ///< H_SS − R_FSᵀR_FS: information passed to the parent
  Eigen::VectorXd marginal_g;  ///< g_S + R_FSᵀd
  bool alive = false;
  bool fresh = false;  ///< built in the current update (must be back-substituted)
};

/// The cliques of a forest of Bayes trees over the free variables of a Values layout. Clique
/// ids are stable until the clique is removed; removed ids are reused.
class BayesTree {
 public:
  /// Sets the dimension and the offset in the delta vector of every variable slot (slots may
  /// only be appended between calls; the tree keeps its cliques).
  void set_layout(const std::vector<int>& dims, const std::vector<int>& offsets);

  /// Removes every clique.
  void clear();
  bool empty() const { return num_cliques_ == 0; }
  int num_cliques() const { return num_cliques_; }
  /// Upper bound of clique ids (some may be dead; check Clique::alive).
  int clique_capacity() const { return static_cast<int>(cliques_.size()); }
  const Clique& clique(int id) const { return cliques_[id]; }
  /// The clique whose frontals hold the variable, or −1.
  int clique_of(int slot) const { return clique_of_[slot]; }
  /// Ids of the root cliques.
  std::vector<int> roots() const;

  /// Removes the cliques holding any of the `marked` variables together with all their
  /// ancestors (the "top" of the tree ISAM2 re-eliminates). Returns the frontal variables of the
  /// removed cliques in `vars`, the factors they held in `factors`, and in `orphans` the
  /// surviving cliques whose parent was removed.
  void detach(const std::vector<int>& marked, std::vector<int>* vars, std::vector<int>* factors,
              std::vector<int>* orphans);

  /// Gives factor `factor` on the free variables `vars` to a clique that already has all of
  /// them (frontal or separator), without changing its numbers: for a factor that adds
  /// nothing (LinearizedFactor::zero). False, and nothing held, if no clique has them all.
  bool hold(int factor, const std::vector<int>& vars);
  /// A clique that has all of `vars` (frontal or separator), or −1.
  int holder(const std::vector<int>& vars) const;
  /// Takes factor `factor` on `vars` from the clique holding it, if any, without changing its
  /// numbers: for a removed factor that added nothing.
  void release(int factor, const std::vector<int>& vars);

  /// Symbolic elimination of `vars` in the order `order` (order[k] indexes vars) with the given
  /// factors (all of whose free variables lie in vars) and orphan subtrees (whose separators lie
  /// in vars). Creates the new cliques (supernodes of the elimination tree), assigns factors and
  /// reattaches orphans; returns the new clique ids, children before parents.
  std::vector<int> build(const std::vector<int>& vars, const std::vector<int>& order,
                         const std::vector<int>& factors,
                         const std::vector<LinearizedFactor>& linearized,
                         const std::vector<int>& orphans);

  /// Numeric elimination of the cliques returned by build() (children first). `damping`, if
  /// not null, is added to the diagonal of H for the frontal variables (laid out like delta).
  /// Returns false with a reason naming a variable slot if a frontal block is not positive
  /// definite; `bad_slot` receives that slot.
  bool factorize(const std::vector<int>& cliques, const std::vector<LinearizedFactor>& linearized,
                 const Eigen::VectorXd* damping, int* bad_slot);

  /// Back-substitution from the roots into `delta` (laid out by the layout's offsets). Fresh
  /// cliques are always solved; others only when a separator variable changed by more than
  /// `wildfire` (max-abs) in this pass, so descending stops where the change dies out. The
  /// variables whose value changed at all are appended to `changed`. Returns the number of
  /// cliques solved.
  int back_substitute(double wildfire, Eigen::VectorXd& delta, std::vector<int>* changed);

  /// Marks every clique not fresh (call after the update is finished).
  void clear_fresh();

  /// Steepest-descent direction of ½‖Rδ − d‖² at δ = 0, i.e. Rᵀd (laid out like delta), and
  /// ‖R v‖² for a vector v; used by the Dogleg step.
  void gradient(Eigen::VectorXd& out) const;
  double r_norm_squared(const Eigen::VectorXd& v) const;
  /// ½‖Rδ − d‖² summed over all cliques (the linear model's cost minus a constant).
  double model_cost(const Eigen::VectorXd& delta) const;

  /// Checks the tree's invariants: parent/child links agree, each live clique's separator is a
  /// subset of its parent's variables (empty for roots), every free variable in `expected_vars`
  /// is frontal in exactly one clique, and every factor index in `expected_factors` is held by
  /// exactly one clique (and no other is). Returns an empty string or the first violation.
  std::string check_invariants(const std::vector<int>& expected_vars,
                               const std::vector<int>& expected_factors) const;

 private:
  int new_clique();
  void remove_clique(int id);

  std::vector<Clique> cliques_;
  std::vector<int> free_ids_;
  int num_cliques_ = 0;
  std::vector<int> clique_of_;  // per slot
  std::vector<int> dims_, offsets_;
  // Scratch indexed by slot (reset after use).
  std::vector<int> pos_;
  std::vector<int> local_offset_;
  std::vector<char> changed_flag_;
  Eigen::MatrixXd work_H_;
  Eigen::VectorXd work_g_, work_x_;
};

}  // namespace kinograph::graph

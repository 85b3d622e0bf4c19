#pragma once
// The Gauss–Newton normal equations H δ = −g (H = JᵀJ, g = Jᵀr over the free variables) in a
// sparse form whose pattern is computed once per graph structure. Each linearization writes
// every factor's dense JᵀJ blocks straight into precomputed slots of H: no sparse J is formed and
// nothing is allocated.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "kinograph/graph/factor_graph.h"
#include "kinograph/graph/ordering.h"
#include "kinograph/graph/share_out_choice.h"
#include "kinograph/graph/values.h"

namespace kinograph::graph {

/// Structure and storage of H (upper triangle, compressed columns, columns in elimination order)
/// and g for one (graph structure, Values layout) pair.
class NormalEquations {
 public:
  /// Builds the pattern. Throws std::invalid_argument naming the factor and key if a factor's
  /// key is missing from `values` or has another dimension. Factors whose keys are all fixed
  /// still contribute to the error. With `threads` > 1 the factors may be evaluated on up to
  /// that many threads (share_out, when ShareOutChoice finds it pays; those not
  /// Factor::parallel_safe on the caller's) and are added
  /// into H and g in graph order afterwards, so H, g and the cost are the same to the bit for
  /// any number of threads.
  NormalEquations(const FactorGraph& graph, const Values& values, OrderingMethod ordering,
                  int threads = 1);

  /// Whether this structure was built for the graph's and values' current structure.
  bool matches(const FactorGraph& graph, const Values& values) const {
    return graph.structure_id() == graph_id_ && values.layout_id() == layout_id_;
  }

  /// Fills H and g at `values` and returns the cost ½Σ‖r‖² through `error`. Returns false with
  /// a reason naming the factor (index and name) if a residual or Jacobian is not finite.
  bool linearize(const FactorGraph& graph, const Values& values, double* error,
                 std::string* reason);
  /// The cost only (no Jacobians). False with a reason if a residual is not finite.
  bool evaluate_error(const FactorGraph& graph, const Values& values, double* error,
                      std::string* reason);

  /// Scalar size of H (sum of free variable dimensions).
  int dim() const { return n_; }
  int num_free_variables() const { return static_cast<int>(var_slot_.size()); }
  const std::vector<int>& col_ptr() const { return col_ptr_; }
  const std::vector<int>& row_idx() const { return row_idx_; }
  /// H's upper-triangle values, in pattern order.
  const std::vector<double>& hessian() const { return h_; }
  /// Positions of H's diagonal entries in hessian().
  const std::vector<int>& diagonal_positions() const { return diag_pos_; }
  /// g = Jᵀr, in elimination order.
  const Eigen::VectorXd& gradient() const { return g_; }
  /// H·v for v in elimination order (uses the upper triangle twice).
  void multiply(const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::Ref<Eigen::VectorXd> out) const;

  /// x ← x + step on the free variables, with x laid out like Values::vector() and the step
  /// in elimination order.
  void add_step(const Eigen::Ref<const Eigen::VectorXd>& step, Eigen::Ref<Eigen::VectorXd> x) const;
  /// Values-layout slot of the free variable eliminated k-th.
  const std::vector<int>& elimination_slots() const { return var_slot_; }
  /// The variable whose block holds scalar column `col` of H.
  Key key_of_column(int col, const Values& values) const;

 private:
  // A stretch of one column of H that a factor's JᵀJ adds to: consecutive entries of H and of
  // a column of JᵀJ's upper triangle (or, mirrored, of a row of it), merged across the blocks
  // of the factor's keys so that small blocks (2×2 for a planar arm) add in one loop.
  struct Run {
    size_t dst;     // index in h_ of the first entry
    int col;        // the column of H
    int src_col;    // JᵀJ's entry (src_row, src_col) is the first added; the next ones go
    int src_row;    // down its column, or along its row when mirrored
    int length;
    bool mirrored;  // below JᵀJ's diagonal: only the upper triangle is written
  };
  struct FactorInfo {
    int slot;       // graph slot
    int first_key;  // into key_value_offset_ / key_col_ (one entry per key)
    int first_run;  // into runs_
    int num_runs;   // 0: the factor has no free key and adds nothing to H
  };
  // A linear factor's whitened J and JᵀJ (upper triangle), kept under its
  // Factor::jacobian_version (−1: none yet).
  struct LinearCache {
    long version = -1;
    Eigen::MatrixXd J, JtJ;
  };
  struct Incidence;     // the free variables and each factor's keys, while building
  struct BlockPattern;  // per block column: its block rows and their offsets in the column
  // One worker's scratch, sized for the largest factor.
  struct Workspace {
    Eigen::VectorXd r, Jtr;
    Eigen::MatrixXd J, JtJ;
    RowSupport support;
    std::vector<const double*> x_ptrs;
  };
  // One factor's evaluation, between computing it and adding it into H and g.
  struct Outcome {
    double half_squared = 0;         // ½‖r‖²
    const char* non_finite = nullptr;  // "residual" or "Jacobian" when one is not finite
    const double* jtj = nullptr;     // JᵀJ (upper triangle, column-major); null: adds nothing
    Eigen::Index stride = 0;         // outer stride of jtj
    const double* jtr = nullptr;     // Jᵀr
  };

  // Construction, in the constructor's order.
  static Incidence incidence(const FactorGraph& graph, const Values& values);
  static void add_factor_keys(size_t fi, const Factor& f, const Values& values, Incidence& inc);
  std::vector<int> assign_columns(const std::vector<int>& order, const Incidence& inc,
                                  const Values& values);
  std::vector<std::vector<int>> lay_out_columns(std::vector<std::vector<int>>& block_rows);
  void allocate_storage();
  void index_factors(const FactorGraph& graph, const Values& values, const Incidence& inc,
                     const std::vector<int>& pos_of_natural, const BlockPattern& pattern);
  std::vector<int> place_keys(const std::vector<int>& slots, const Values& values,
                              const Incidence& inc, const std::vector<int>& pos_of_natural);
  void add_runs(const Factor& f, const std::vector<int>& pos, const BlockPattern& pattern,
                FactorInfo& info);
  void size_workspaces(const FactorGraph& graph, const Incidence& inc);

  // Evaluation of every factor, on one thread or on several (this is the solvers' hot path).
  template <bool kWithJacobian>
  bool run(const FactorGraph& graph, const Values& values, double* error, std::string* reason);
  // Factor fi (index into factors_) at x = base: r, and with kWithJacobian JᵀJ and Jᵀr written
  // to jtj (outer stride `stride`) and jtr unless a kept linear factor's own serve.
  template <bool kWithJacobian>
  Outcome evaluate(size_t fi, const FactorGraph& graph, const double* base, Workspace& ws,
                   double* jtj, Eigen::Index stride, double* jtr);
  // Adds factor fi's evaluation into the columns [first_col, end_col) of H and g.
  void add(size_t fi, const Factor& f, const Outcome& o, int first_col, int end_col);
  // Adds the shared evaluation (outcomes_) into H and g, zeroed first: each worker takes a
  // part of the columns and adds to it in graph order, so every entry is the serial sum.
  void add_in_parallel(const FactorGraph& graph);
  // The parallel evaluation into outcomes_ (and the scratch); false when nothing is run so.
  template <bool kWithJacobian>
  bool evaluate_in_parallel(const FactorGraph& graph, const double* base);
  Workspace& workspace(int worker);

  uint64_t graph_id_ = 0;
  uint64_t layout_id_ = 0;
  int n_ = 0;
  std::vector<int> var_slot_;          // free variable (elimination order) → Values slot
  std::vector<int> var_col_;           // free variable → first scalar column of H
  std::vector<int> var_value_offset_;  // free variable → offset in Values::vector()
  std::vector<int> var_dim_;
  std::vector<int> col_ptr_, row_idx_, diag_pos_;
  std::vector<double> h_;
  Eigen::VectorXd g_;
  std::vector<FactorInfo> factors_;
  std::vector<int> key_value_offset_;  // per factor key: offset into Values::vector()
  std::vector<int> key_col_;           // per factor key: first column of H, −1 if fixed
  std::vector<Run> runs_;
  std::vector<LinearCache> linear_;  // one per entry of factors_
  // Threads: each worker's workspace (made by the worker on first use), the factors that may
  // run on any worker and those that run on the caller's, and per factor its last evaluation
  // and the place of its JᵀJ and Jᵀr in the caller's scratch (buffer_size_ doubles in all).
  int threads_ = 1;
  int max_rows_ = 0, max_cols_ = 0, max_keys_ = 0;
  std::vector<Workspace> workspaces_;
  std::vector<int> any_worker_, caller_only_;
  std::vector<Outcome> outcomes_;
  std::vector<size_t> buffer_offset_;
  size_t buffer_size_ = 0;
  // The scatter's column parts: part p is columns part_cols_[p] … part_cols_[p + 1] − 1, at
  // variable boundaries; parts_ lists 0 … P − 1 for share_out.
  std::vector<int> part_cols_, parts_;
  // Whether sharing out pays, for evaluations without and with Jacobians.
  ShareOutChoice choice_[2];
};

}  // namespace kinograph::graph

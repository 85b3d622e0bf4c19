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
#include "kinograph/graph/values.h"

namespace kinograph::graph {

/// Structure and storage of H (upper triangle, compressed columns, columns in elimination order)
/// and g for one (graph structure, Values layout) pair.
class NormalEquations {
 public:
  /// Builds the pattern. Throws std::invalid_argument naming the factor and key if a factor's
  /// key is missing from `values` or has another dimension. Factors whose keys are all fixed
  /// still contribute to the error.
  NormalEquations(const FactorGraph& graph, const Values& values, OrderingMethod ordering);

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

  /// delta (laid out like Values::vector(), zero on fixed variables) from a step in elimination
  /// order.
  void scatter_step(const Eigen::Ref<const Eigen::VectorXd>& step,
                    Eigen::Ref<Eigen::VectorXd> delta) const;
  /// The variable whose block holds scalar column `col` of H.
  Key key_of_column(int col, const Values& values) const;

 private:
  struct Pair {     // one upper block of H touched by a factor
    int col_block;  // factor-local key index of the block column (later in elimination)
    int row_block;  // factor-local key index of the block row
    int first_pos;  // position in h_ of entry (first row of row block, first column)
    bool diagonal;
  };
  struct FactorInfo {
    int slot;                   // graph slot
    int first_var;              // into var_ptr_offsets_ (one per key)
    int first_pair, num_pairs;  // into pairs_
  };

  uint64_t graph_id_ = 0;
  uint64_t layout_id_ = 0;
  int n_ = 0;
  std::vector<int> var_slot_;     // free variable (elimination order) → Values slot
  std::vector<int> var_col_;      // free variable → first scalar column of H
  std::vector<int> slot_to_var_;  // Values slot → free variable or −1 if fixed
  std::vector<int> col_ptr_, row_idx_, diag_pos_;
  std::vector<int> col_stride_;  // per scalar column of a block: positions step between columns
  std::vector<double> h_;
  Eigen::VectorXd g_;
  std::vector<FactorInfo> factors_;
  std::vector<int> key_value_offset_;  // per factor key: offset into Values::vector()
  std::vector<int> key_col_;           // per factor key: first column of H, −1 if fixed
  std::vector<Pair> pairs_;
  // Workspaces sized for the largest factor.
  Eigen::VectorXd r_;
  Eigen::MatrixXd J_, JtJ_;
  Eigen::VectorXd Jtr_;
  std::vector<const double*> x_ptrs_;
};

}  // namespace kinograph::graph

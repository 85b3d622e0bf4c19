#pragma once
// The whole linearized system of ISAM2's factors, Σ H_f δ = −Σ g_f over the free variables,
// assembled with its columns in slot order and factorized within its envelope. For a chain (a
// trajectory whose variables were added in time order) that is a band, and solving it costs a
// fraction of rebuilding the Bayes tree: how ISAM2 takes a Gauss–Newton step that relinearizes
// most variables (ISAM2Options::banded_full_updates).
#include <Eigen/Core>
#include <memory>
#include <vector>

#include "kinograph/graph/bayes_tree.h"
#include "kinograph/graph/envelope_cholesky.h"

namespace kinograph::graph {

/// Σ H_f and Σ g_f of a set of linearized factors, and their damped solution.
class BandedSystem {
 public:
  /// Sets up the pattern of Σ H_f over `factors` (indices into `linearized`) with the blocks of
  /// `free_slots` (increasing) as columns, `dims` giving every slot's dimension. The pattern and
  /// its factorization are kept while the variables' adjacency stays the same. Returns whether
  /// the envelope factorization suits the pattern (EnvelopeCholesky::wins); when it does not,
  /// assemble() and solve() must not be called.
  bool prepare(const std::vector<int>& free_slots, const std::vector<int>& dims,
               const std::vector<LinearizedFactor>& linearized, const std::vector<int>& factors);

  /// Sums the factors' H and g (those with an active row) into the prepared pattern.
  void assemble(const std::vector<LinearizedFactor>& linearized, const std::vector<int>& factors);

  /// Solves (H + diag(damping)) δ = −g and writes δ of every free slot s at offsets[s] of
  /// `delta` (`damping`, if given, is indexed the same way). False when H + diag(damping) is
  /// not positive definite; then `bad_slot` is the slot where the factorization broke down.
  bool solve(const Eigen::VectorXd* damping, const std::vector<int>& offsets,
             Eigen::VectorXd& delta, int* bad_slot);

 private:
  // Where block (a, b) of H, col(a) < col(b), starts in each column of b: col_ptr_ of that
  // column plus this offset.
  int row_offset(int b, int a) const;
  // Adds block (a, b) (or the upper triangle of (b, b)) of a factor's H.
  void add_block(const Eigen::MatrixXd& H, int row, int col, int a, int b);

  std::vector<int> signature_, signature_scratch_;  // the factors' variables, −1 after each
  std::vector<int> slots_;                          // free slots, in column order
  std::vector<int> column_;                         // per slot: first column, −1 if not free
  std::vector<int> dim_;                            // per slot
  std::vector<std::vector<int>> lower_;             // per slot: free neighbours left of it, sorted
  std::vector<std::vector<int>> lower_rows_;        // per slot: row offset of each of them
  std::vector<int> diagonal_row_;                   // per slot: row offset of its diagonal block
  std::vector<int> col_ptr_, row_idx_;
  std::vector<double> h_;  // Σ H_f, pattern order
  Eigen::VectorXd g_, rhs_, x_;
  std::unique_ptr<EnvelopeCholesky> cholesky_;  // null when the envelope does not win
};

}  // namespace kinograph::graph

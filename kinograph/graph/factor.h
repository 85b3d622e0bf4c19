#pragma once
// A factor is one term ½‖r(x)‖² of the least-squares cost over a few variables. Authors
// implement evaluate() (raw error and its Jacobian blocks); the noise model whitens both.
#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "kinograph/graph/key.h"
#include "kinograph/graph/noise_model.h"
#include "kinograph/graph/values.h"

namespace kinograph::graph {

/// Read-only view of the current values of one factor's variables, in the factor's key order.
class FactorValues {
 public:
  FactorValues(const double* const* data, const int* dims) : data_(data), dims_(dims) {}
  /// The i-th variable of the factor (i indexes keys()).
  Eigen::Map<const Eigen::VectorXd> operator[](int i) const { return {data_[i], dims_[i]}; }

 private:
  const double* const* data_;
  const int* dims_;
};

/// The rows of a whitened Jacobian that may be non-zero. A factor with many rows that are
/// usually inactive (a collision hinge per pair) lists them, so a solver touches only those.
struct RowSupport {
  bool all = true;        ///< every row may be non-zero (`rows` unused)
  std::vector<int> rows;  ///< otherwise these, ascending; the other rows hold anything
};

/// Writable view of a factor's Jacobian, one dense block per key, stacked side by side in key
/// order (residual_dim rows). Blocks arrive zeroed, so authors fill only non-zero entries
/// (except with a row list for a factor that writes_listed_rows_only()).
class Jacobians {
 public:
  using Block = Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>>;
  Jacobians(double* data, Eigen::Index rows, Eigen::Index outer_stride, const int* col_offsets,
            const int* dims, RowSupport* support = nullptr)
      : data_(data),
        rows_(rows),
        stride_(outer_stride),
        offsets_(col_offsets),
        dims_(dims),
        support_(support) {}
  /// de/dx_i: residual_dim × dim(key i).
  Block block(int i) const {
    return Block(data_ + offsets_[i] * stride_, rows_, dims_[i], Eigen::OuterStride<>(stride_));
  }
  /// Where the caller takes a list of the rows that may be non-zero (null: it reads every row,
  /// which must then hold the Jacobian).
  RowSupport* row_support() const { return support_; }

 private:
  double* data_;
  Eigen::Index rows_;
  Eigen::Index stride_;
  const int* offsets_;
  const int* dims_;
  RowSupport* support_;
};

/// One cost term over a fixed set of vector variables. Keys, their dimensions and the residual
/// dimension never change after construction (the solvers cache structure on them); the noise
/// model and any targets held by a subclass may change between solves.
class Factor {
 public:
  /// Throws std::invalid_argument on an empty key list, duplicate keys, sizes that disagree,
  /// non-positive dimensions, or a noise model of another dimension. A null noise model means
  /// unit (r = e).
  Factor(std::vector<Key> keys, std::vector<int> dims, int residual_dim,
         NoiseModelPtr noise = nullptr);
  virtual ~Factor() = default;

  /// The raw error e(x) and, if J is non-null, its Jacobian blocks de/dx_i (zeroed on entry).
  virtual void evaluate(const FactorValues& x, Eigen::Ref<Eigen::VectorXd> e,
                        const Jacobians* J) const = 0;

  /// Name used in error messages; defaults to the demangled class name.
  virtual std::string name() const;

  const std::vector<Key>& keys() const { return keys_; }
  /// Renames the factor's variables (`rename` must keep distinct keys distinct); what it
  /// computes is unchanged, since evaluate() reads its variables by position. For renaming a
  /// whole graph's variables at once (ISAM2::rename_variables). Throws std::invalid_argument when
  /// two keys would merge.
  void rename_keys(const std::function<Key(Key)>& rename);
  /// Dimension of each key's variable, in key order.
  const std::vector<int>& dims() const { return dims_; }
  /// Column of key i's block in the stacked Jacobian.
  const std::vector<int>& block_offsets() const { return offsets_; }
  int residual_dim() const { return residual_dim_; }
  /// Sum of the key dimensions (columns of the stacked Jacobian).
  int jacobian_cols() const { return cols_; }

  const NoiseModelPtr& noise() const { return noise_; }
  /// Replaces the noise model (same dimension; throws std::invalid_argument otherwise). Keeps the
  /// graph structure, so solvers reuse their symbolic analysis.
  void set_noise(NoiseModelPtr noise);

  /// Whitened residual r (resized to residual_dim) and whitened stacked Jacobian J (resized to
  /// residual_dim × jacobian_cols) at `values`. Fixed variables get blocks like any other.
  /// Throws std::out_of_range if a key is missing and std::invalid_argument if a dimension
  /// differs. Does not check for NaN (see all_finite()).
  void linearize(const Values& values, Eigen::VectorXd& r, Eigen::MatrixXd& J) const;
  /// Whitened residual only.
  void whitened_residual(const Values& values, Eigen::VectorXd& r) const;
  /// Cost ½‖r‖² of this factor at `values`.
  double error(const Values& values) const;

  /// Raw-pointer entry used by the solvers' hot loops: `x` holds one pointer per key; `J` may be
  /// null. Applies the noise model. With `support` (and J) the factor may say which rows of J
  /// may be non-zero; the others are then left as they are, and the caller must not read them.
  void whitened(const double* const* x, Eigen::Ref<Eigen::VectorXd> r,
                Eigen::Ref<Eigen::MatrixXd>* J, RowSupport* support = nullptr) const;

  /// Whether evaluate() may run on a pool thread while other factors of its graph are being
  /// evaluated: it touches only the factor's own state, thread_local scratch and WorkerLocal
  /// workspaces. A factor that shares a plain workspace with others keeps the default (false)
  /// and is evaluated on the caller's thread.
  virtual bool parallel_safe() const { return false; }

  /// Whether, when given a row list (Jacobians::row_support()), evaluate() writes every row it
  /// lists in full (the rows it leaves out hold anything): J then arrives unzeroed (whitened()
  /// skips zeroing it), which spares a factor whose rows are mostly zero (clear collision
  /// pairs) clearing them all on every linearization. Without a row list J arrives zeroed.
  virtual bool writes_listed_rows_only() const { return false; }

  /// For a factor linear in its variables (its whitened Jacobian then does not depend on them),
  /// a number that changes whenever that Jacobian may change (noise model, penalty); −1 for
  /// every other factor. Numbers are unique across all factors of the process, so a solver may
  /// keep J and JᵀJ under this number alone.
  long jacobian_version() const {
    return linear_ && (!noise_ || noise_->constant_whitening()) ? jacobian_version_ : -1;
  }

 protected:
  /// Declares evaluate() linear in the variables (the test suite checks the Jacobian is constant).
  void set_linear() { linear_ = true; }
  /// Marks a change of something, besides the noise model, the whitened Jacobian depends on.
  void jacobian_changed();

 private:
  std::vector<Key> keys_;
  std::vector<int> dims_;
  std::vector<int> offsets_;
  int residual_dim_;
  int cols_;
  NoiseModelPtr noise_;
  bool linear_ = false;
  long jacobian_version_ = 0;
};

/// True when every entry of `M` is finite. One vectorized sum (M·0 is NaN exactly where M is
/// not finite) instead of Eigen's entry-by-entry test, which dominated checking big Jacobians.
bool all_finite(const Eigen::Ref<const Eigen::MatrixXd>& M);

/// Moves the rows of a whitened Jacobian that are not all zero to its top (with their
/// residuals) and returns how many there are. Inactive inequality rows (a collision hinge far
/// from its bound) are exactly zero and add nothing to JᵀJ or Jᵀr; a collision factor has a row
/// per (link, obstacle) pair and usually one or none active, so products over the kept rows
/// skip most of the work. Order of the kept rows is preserved.
/// With `finite` non-null it also says whether every entry of J is finite, from the same pass
/// (then J and r are left as they were when it is false).
/// With `support`, only its rows are read (and checked for finiteness); the result is the same
/// as for a J that is zero outside them.
int compact_nonzero_rows(Eigen::Ref<Eigen::MatrixXd> J, Eigen::Ref<Eigen::VectorXd> r,
                         bool* finite = nullptr, const RowSupport* support = nullptr);

/// H = JᵀJ of a factor's (kept) Jacobian rows. From 16 columns on (GP prior, collocation) a
/// symmetric rank update, half the flops of the product (21×42: 3.1 instead of 4.4 µs); below,
/// the plain small product. With `upper_only` the strictly lower triangle is left unspecified.
void jacobian_gram(const Eigen::Ref<const Eigen::MatrixXd>& J, Eigen::Ref<Eigen::MatrixXd> H,
                   bool upper_only);

}  // namespace kinograph::graph

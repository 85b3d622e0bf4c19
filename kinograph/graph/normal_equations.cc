#include "kinograph/graph/normal_equations.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "kinograph/graph/cancellation.h"
#include "kinograph/graph/worker_pool.h"

namespace kinograph::graph {

namespace {

// Factors linearized between two looks at the cancellation flag: a few hundred microseconds.
constexpr size_t kFactorsPerCancellationCheck = 256;
// Graphs with fewer factors that may run on any thread than this are evaluated on the caller's
// alone: sharing the work out would cost about as much as it saves.
constexpr size_t kMinParallelFactors = 32;
// Factors a worker takes at a time.
constexpr size_t kChunk = 4;

// How messages name a factor: "factor 3 (Name)".
std::string factor_label(size_t index, const Factor& f) {
  return "factor " + std::to_string(index) + " (" + f.name() + ")";
}

// The Values slot of the factor's k-th key; throws if the key is missing or has another
// dimension.
int checked_slot(const Values& values, const Factor& f, size_t fi, size_t k) {
  const Key key = f.keys()[k];
  const int s = values.find(key);
  if (s < 0) {
    throw std::invalid_argument(factor_label(fi, f) + " uses " + key.to_string() +
                                ", which is not in Values");
  }
  if (values.dim(s) != f.dims()[k]) {
    throw std::invalid_argument(factor_label(fi, f) + " expects " + key.to_string() +
                                " of dimension " + std::to_string(f.dims()[k]) + ", Values has " +
                                std::to_string(values.dim(s)));
  }
  return s;
}

// Block pattern: for each block column b, the block rows a ≤ b coupled to it (always b),
// unsorted and with repeats.
std::vector<std::vector<int>> coupled_block_rows(const std::vector<std::vector<int>>& factor_vars,
                                                 const std::vector<int>& pos_of_natural) {
  const int num_free = static_cast<int>(pos_of_natural.size());
  // Counted first, so that each column's list is allocated once.
  std::vector<int> count(num_free, 1);
  for (const auto& vars : factor_vars) {
    for (int va : vars) {
      for (int vb : vars) count[pos_of_natural[vb]] += pos_of_natural[va] < pos_of_natural[vb];
    }
  }
  std::vector<std::vector<int>> block_rows(num_free);
  for (int b = 0; b < num_free; ++b) {
    block_rows[b].reserve(count[b]);
    block_rows[b].push_back(b);
  }
  for (const auto& vars : factor_vars) {
    for (int va : vars) {
      for (int vb : vars) {
        const int a = pos_of_natural[va], b = pos_of_natural[vb];
        if (a < b) block_rows[b].push_back(a);
      }
    }
  }
  return block_rows;
}

}  // namespace

// Free variables in slot order ("natural" index) and, per factor, the slots of its keys.
struct NormalEquations::Incidence {
  std::vector<int> natural_of_slot;  // −1 for a fixed slot
  std::vector<int> slot_of_natural;
  std::vector<std::vector<int>> factor_vars;     // per factor: natural indices of its free keys
  std::vector<std::vector<int>> factor_slots;    // per factor: the slot of every key
  int max_rows = 0, max_cols = 0, max_keys = 0;  // the largest factor, for the workspaces
};

struct NormalEquations::BlockPattern {
  std::vector<std::vector<int>> rows;    // per block column: sorted block rows a ≤ b
  std::vector<std::vector<int>> within;  // per block column: each row's first scalar offset
};

NormalEquations::NormalEquations(const FactorGraph& graph, const Values& values,
                                 OrderingMethod ordering, int threads)
    : graph_id_(graph.structure_id()),
      layout_id_(values.layout_id()),
      threads_(std::clamp(threads, 1, kMaxWorkers)) {
  const Incidence inc = incidence(graph, values);
  const int num_free = static_cast<int>(inc.slot_of_natural.size());
  const std::vector<int> order = compute_ordering(num_free, inc.factor_vars, ordering);
  const std::vector<int> pos_of_natural = assign_columns(order, inc, values);
  BlockPattern pattern;
  pattern.rows = coupled_block_rows(inc.factor_vars, pos_of_natural);
  pattern.within = lay_out_columns(pattern.rows);
  allocate_storage();
  index_factors(graph, values, inc, pos_of_natural, pattern);
  size_workspaces(graph, inc);
}

NormalEquations::Incidence NormalEquations::incidence(const FactorGraph& graph,
                                                      const Values& values) {
  Incidence inc;
  inc.natural_of_slot.assign(values.size(), -1);
  for (int s = 0; s < values.size(); ++s) {
    if (!values.is_fixed_slot(s)) {
      inc.natural_of_slot[s] = static_cast<int>(inc.slot_of_natural.size());
      inc.slot_of_natural.push_back(s);
    }
  }
  inc.factor_vars.reserve(graph.num_factors());
  inc.factor_slots.reserve(graph.num_factors());
  for (size_t fi = 0; fi < graph.size(); ++fi) {
    if (graph[fi]) add_factor_keys(fi, *graph[fi], values, inc);
  }
  return inc;
}

// Checks and records one factor's keys (fi is its graph slot, for messages).
void NormalEquations::add_factor_keys(size_t fi, const Factor& f, const Values& values,
                                      Incidence& inc) {
  std::vector<int> vars, slots;
  vars.reserve(f.keys().size());
  slots.reserve(f.keys().size());
  for (size_t k = 0; k < f.keys().size(); ++k) {
    const int s = checked_slot(values, f, fi, k);
    slots.push_back(s);
    if (inc.natural_of_slot[s] >= 0) vars.push_back(inc.natural_of_slot[s]);
  }
  inc.factor_vars.push_back(std::move(vars));
  inc.factor_slots.push_back(std::move(slots));
  inc.max_rows = std::max(inc.max_rows, f.residual_dim());
  inc.max_cols = std::max(inc.max_cols, f.jacobian_cols());
  inc.max_keys = std::max(inc.max_keys, static_cast<int>(f.keys().size()));
}

// Elimination order and scalar columns; returns each natural variable's position in the order.
std::vector<int> NormalEquations::assign_columns(const std::vector<int>& order,
                                                 const Incidence& inc, const Values& values) {
  const int num_free = static_cast<int>(inc.slot_of_natural.size());
  std::vector<int> pos_of_natural(num_free);
  var_slot_.resize(num_free);
  var_col_.resize(num_free);
  var_value_offset_.resize(num_free);
  var_dim_.resize(num_free);
  for (int k = 0; k < num_free; ++k) {
    pos_of_natural[order[k]] = k;
    const int s = inc.slot_of_natural[order[k]];
    var_slot_[k] = s;
    var_col_[k] = n_;
    var_value_offset_[k] = values.offset(s);
    var_dim_[k] = values.dim(s);
    n_ += var_dim_[k];
  }
  return pos_of_natural;
}

// Sorts each block column's rows, fills col_ptr_ and row_idx_, and returns the offset of each
// block row inside its block column (the same for every scalar column).
std::vector<std::vector<int>> NormalEquations::lay_out_columns(
    std::vector<std::vector<int>>& block_rows) {
  const int num_free = static_cast<int>(block_rows.size());
  std::vector<std::vector<int>> block_within(num_free);
  col_ptr_.assign(n_ + 1, 0);
  for (int b = 0; b < num_free; ++b) {
    auto& rows = block_rows[b];
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    int within = 0;
    block_within[b].reserve(rows.size());
    for (int a : rows) {
      block_within[b].push_back(within);
      within += var_dim_[a];
    }
    const int off_diagonal = within - var_dim_[b];
    for (int k = 0; k < var_dim_[b]; ++k) {
      const int c = var_col_[b] + k;
      col_ptr_[c + 1] = col_ptr_[c] + off_diagonal + k + 1;
      for (int a : rows) {
        const int rows_here = a == b ? k + 1 : var_dim_[a];
        for (int r = 0; r < rows_here; ++r) row_idx_.push_back(var_col_[a] + r);
      }
    }
  }
  return block_within;
}

// Diagonal positions, and H and g zeroed, for the laid-out pattern.
void NormalEquations::allocate_storage() {
  diag_pos_.resize(n_);
  for (int c = 0; c < n_; ++c) diag_pos_[c] = col_ptr_[c + 1] - 1;
  h_.assign(row_idx_.size(), 0.0);
  g_.setZero(n_);
}

// Per factor: where its keys live in Values and H, and the upper blocks of H it touches.
void NormalEquations::index_factors(const FactorGraph& graph, const Values& values,
                                    const Incidence& inc, const std::vector<int>& pos_of_natural,
                                    const BlockPattern& pattern) {
  size_t fi_dense = 0;
  factors_.reserve(inc.factor_slots.size());
  size_t keys = 0;
  for (const auto& slots : inc.factor_slots) keys += slots.size();
  key_value_offset_.reserve(keys);
  key_col_.reserve(keys);
  for (size_t fi = 0; fi < graph.size(); ++fi) {
    if (!graph[fi]) continue;
    const auto& slots = inc.factor_slots[fi_dense++];
    FactorInfo info{static_cast<int>(fi), static_cast<int>(key_col_.size()),
                    static_cast<int>(runs_.size()), 0};
    const std::vector<int> pos = place_keys(slots, values, inc, pos_of_natural);
    add_runs(*graph[fi], pos, pattern, info);
    factors_.push_back(info);
  }
}

// Appends a factor's keys to key_value_offset_ and key_col_; returns each key's elimination
// position (−1 if fixed).
std::vector<int> NormalEquations::place_keys(const std::vector<int>& slots, const Values& values,
                                             const Incidence& inc,
                                             const std::vector<int>& pos_of_natural) {
  std::vector<int> pos(slots.size(), -1);
  for (size_t k = 0; k < slots.size(); ++k) {
    key_value_offset_.push_back(values.offset(slots[k]));
    const int nat = inc.natural_of_slot[slots[k]];
    pos[k] = nat < 0 ? -1 : pos_of_natural[nat];
    key_col_.push_back(nat < 0 ? -1 : var_col_[pos[k]]);
  }
  return pos;
}

// Appends the runs of a factor: for every column of H that one of its free keys holds, the
// upper blocks of its keys in that column in H's row order, each merged into the run before it
// when both continue the same column (or row) of JᵀJ and the same column of H.
void NormalEquations::add_runs(const Factor& f, const std::vector<int>& pos,
                               const BlockPattern& pattern, FactorInfo& info) {
  const auto& offsets = f.block_offsets();
  const auto& dims = f.dims();
  std::vector<int> by_position;  // the free keys in elimination order
  by_position.reserve(pos.size());
  for (size_t i = 0; i < pos.size(); ++i) {
    if (pos[i] >= 0) by_position.push_back(static_cast<int>(i));
  }
  std::sort(by_position.begin(), by_position.end(),
            [&pos](int x, int y) { return pos[x] < pos[y]; });
  for (size_t jj = 0; jj < by_position.size(); ++jj) {
    const int j = by_position[jj], b = pos[j];
    const auto& rows = pattern.rows[b];
    for (int k = 0; k < dims[j]; ++k) {
      const int col = var_col_[b] + k;
      for (size_t ii = 0; ii <= jj; ++ii) {  // the keys at or above the diagonal block
        const int i = by_position[ii], a = pos[i];
        const auto it = std::lower_bound(rows.begin(), rows.end(), a);
        Run run;
        run.dst = static_cast<size_t>(col_ptr_[col] + pattern.within[b][it - rows.begin()]);
        run.col = col;
        run.src_col = offsets[j] + k;
        run.src_row = offsets[i];
        run.length = a == b ? k + 1 : dims[i];
        run.mirrored = offsets[i] > offsets[j];
        if (run.mirrored) std::swap(run.src_col, run.src_row);  // (row, col) of the upper entry
        if (info.num_runs > 0) {
          Run& last = runs_.back();
          const bool along = last.mirrored == run.mirrored && last.col == col &&
                             last.dst + last.length == run.dst;
          const bool next = run.mirrored ? last.src_row == run.src_row &&
                                               last.src_col + last.length == run.src_col
                                         : last.src_col == run.src_col &&
                                               last.src_row + last.length == run.src_row;
          if (along && next) {
            last.length += run.length;
            continue;
          }
        }
        runs_.push_back(run);
        ++info.num_runs;
      }
    }
  }
}

// Linear caches, the workers' workspaces (the caller's at once) and which factors may run on
// any worker.
void NormalEquations::size_workspaces(const FactorGraph& graph, const Incidence& inc) {
  linear_.assign(factors_.size(), LinearCache());
  max_rows_ = inc.max_rows;
  max_cols_ = inc.max_cols;
  max_keys_ = inc.max_keys;
  workspaces_.resize(static_cast<size_t>(threads_));
  workspace(0);
  if (threads_ <= 1) return;
  for (size_t fi = 0; fi < factors_.size(); ++fi) {
    (graph[factors_[fi].slot]->parallel_safe() ? any_worker_ : caller_only_)
        .push_back(static_cast<int>(fi));
  }
}

NormalEquations::Workspace& NormalEquations::workspace(int worker) {
  Workspace& ws = workspaces_[static_cast<size_t>(worker)];
  if (ws.x_ptrs.size() != static_cast<size_t>(max_keys_)) {  // first use by this worker
    ws.r.setZero(max_rows_);
    ws.J.setZero(max_rows_, max_cols_);
    ws.JtJ.setZero(max_cols_, max_cols_);
    ws.Jtr.setZero(max_cols_);
    ws.x_ptrs.resize(max_keys_);
  }
  return ws;
}

template <bool kWithJacobian>
NormalEquations::Outcome NormalEquations::evaluate(size_t fi, const FactorGraph& graph,
                                                   const double* base, Workspace& ws,
                                                   double* jtj, Eigen::Index stride, double* jtr) {
  const FactorInfo& info = factors_[fi];
  const Factor& f = *graph[info.slot];
  const int m = f.residual_dim();
  const int nk = static_cast<int>(f.keys().size());
  for (int k = 0; k < nk; ++k) ws.x_ptrs[k] = base + key_value_offset_[info.first_key + k];
  auto r = ws.r.head(m);
  r.setZero();
  Outcome o;
  if constexpr (!kWithJacobian) {
    f.whitened(ws.x_ptrs.data(), r, nullptr);
    if (!r.allFinite()) {
      o.non_finite = "residual";
      return o;
    }
    o.half_squared = 0.5 * r.squaredNorm();
    return o;
  } else {
    const int nc = f.jacobian_cols();
    // A linear factor whose Jacobian is unchanged keeps J and JᵀJ: only r and Jᵀr are new.
    const long version = f.jacobian_version();
    LinearCache* cache = version >= 0 && info.num_runs > 0 ? &linear_[fi] : nullptr;
    const bool kept = cache != nullptr && cache->version == version;
    Eigen::Ref<Eigen::MatrixXd> J = ws.J.topLeftCorner(m, nc);
    // A kept linear factor's J must be whole; a factor on no free variable is only summed.
    RowSupport* support = cache == nullptr && info.num_runs > 0 ? &ws.support : nullptr;
    f.whitened(ws.x_ptrs.data(), r, kept ? nullptr : &J, support);
    if (!r.allFinite()) {
      o.non_finite = "residual";
      return o;
    }
    // A factor that adds to H learns whether J is finite from the row compaction below.
    if (!kept && info.num_runs == 0 && !all_finite(J)) {
      o.non_finite = "Jacobian";
      return o;
    }
    o.half_squared = 0.5 * r.squaredNorm();
    if (info.num_runs == 0) return o;
    Eigen::Map<Eigen::VectorXd> Jtr(jtr, nc);
    o.jtr = jtr;
    if (kept) {
      Jtr.noalias() = cache->J.transpose() * r;
      o.jtj = cache->JtJ.data();
      o.stride = cache->JtJ.outerStride();
      return o;
    }
    if (cache != nullptr) cache->J = J;  // before the compaction reorders its rows
    bool finite = true;
    const int active = compact_nonzero_rows(J, r, &finite, support);
    if (!finite) {
      o.non_finite = "Jacobian";
      return o;
    }
    if (active == 0) return o;  // e.g. a collision factor with every pair clear
    const auto Ja = J.topRows(active);
    Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>> JtJ(jtj, nc, nc,
                                                             Eigen::OuterStride<>(stride));
    jacobian_gram(Ja, JtJ, /*upper_only=*/true);  // only upper blocks are scattered
    Jtr.noalias() = Ja.transpose() * r.head(active);
    o.jtj = jtj;
    o.stride = stride;
    if (cache != nullptr) {
      cache->JtJ = JtJ;
      cache->version = version;
    }
    return o;
  }
}

void NormalEquations::add(size_t fi, const Factor& f, const Outcome& o, int first_col,
                          int end_col) {
  const FactorInfo& info = factors_[fi];
  const int nk = static_cast<int>(f.keys().size());
  const auto& offsets = f.block_offsets();
  const auto& dims = f.dims();
  for (int k = 0; k < nk; ++k) {
    const int col = key_col_[info.first_key + k];
    if (col >= first_col && col < end_col) {
      g_.segment(col, dims[k]) += Eigen::Map<const Eigen::VectorXd>(o.jtr + offsets[k], dims[k]);
    }
  }
  const double* jtj = o.jtj;
  const Eigen::Index stride = o.stride;
  double* h = h_.data();
  for (int p = info.first_run; p < info.first_run + info.num_runs; ++p) {
    const Run& run = runs_[p];
    if (run.col < first_col || run.col >= end_col) continue;
    double* dst = h + run.dst;
    const double* src = jtj + run.src_col * stride + run.src_row;
    if (!run.mirrored) {  // down a column of JᵀJ's upper triangle
      for (int i = 0; i < run.length; ++i) dst[i] += src[i];
    } else {  // along a row of it: the mirrored entries of the lower triangle
      for (int i = 0; i < run.length; ++i) dst[i] += src[i * stride];
    }
  }
}

namespace {
// Room for every factor's JᵀJ and Jᵀr of a shared evaluation, from evaluating to adding them
// within one run on the caller's thread: that thread's scratch, which only grows. Solves that
// follow one another reuse it instead of faulting in fresh pages each time.
double* outcome_scratch(size_t size) {
  thread_local std::vector<double> scratch;
  if (scratch.size() < size) scratch.resize(size);
  return scratch.data();
}
}  // namespace

template <bool kWithJacobian>
bool NormalEquations::evaluate_in_parallel(const FactorGraph& graph, const double* base) {
  if (threads_ <= 1 || any_worker_.size() < kMinParallelFactors ||
      !choice_[kWithJacobian].share()) {
    return false;
  }
  if (outcomes_.size() != factors_.size()) {  // first parallel run: where each factor's goes
    outcomes_.resize(factors_.size());
    buffer_offset_.resize(factors_.size());
    buffer_size_ = 0;
    for (size_t fi = 0; fi < factors_.size(); ++fi) {
      buffer_offset_[fi] = buffer_size_;
      const size_t nc = static_cast<size_t>(graph[factors_[fi].slot]->jacobian_cols());
      if (factors_[fi].num_runs > 0) buffer_size_ += nc * nc + nc;
    }
  }
  double* const buffer = outcome_scratch(buffer_size_);
  size_t done = 0;  // by worker 0, which alone looks at the cancellation flag
  auto one = [&](int item, int worker) {
    if (worker == 0 && ++done % kFactorsPerCancellationCheck == 0) throw_if_cancelled();
    const size_t fi = static_cast<size_t>(item);
    const Eigen::Index nc = graph[factors_[fi].slot]->jacobian_cols();
    double* at = buffer + buffer_offset_[fi];
    outcomes_[fi] = evaluate<kWithJacobian>(fi, graph, base, workspace(worker), at + nc, nc, at);
  };
  share_out(threads_, caller_only_, any_worker_, one, kChunk);
  return true;
}

void NormalEquations::add_in_parallel(const FactorGraph& graph) {
  if (part_cols_.empty()) {  // the column parts, once: equal shares of H's entries
    const int parts = std::max(1, std::min(threads_, n_));
    part_cols_.push_back(0);
    for (int v = 0; v < static_cast<int>(var_col_.size()); ++v) {
      const int share = static_cast<int>(part_cols_.size());
      if (share < parts && col_ptr_[var_col_[v]] * static_cast<size_t>(parts) >=
                               static_cast<size_t>(share) * h_.size()) {
        if (var_col_[v] > part_cols_.back()) part_cols_.push_back(var_col_[v]);
      }
    }
    part_cols_.push_back(n_);
    parts_.resize(part_cols_.size() - 1);
    std::iota(parts_.begin(), parts_.end(), 0);
  }
  auto one = [&](int part, int) {
    const int first = part_cols_[part], end = part_cols_[part + 1];
    std::fill(h_.begin() + col_ptr_[first], h_.begin() + col_ptr_[end], 0.0);
    g_.segment(first, end - first).setZero();
    for (size_t fi = 0; fi < factors_.size(); ++fi) {
      const Outcome& o = outcomes_[fi];
      if (o.jtj != nullptr) add(fi, *graph[factors_[fi].slot], o, first, end);
    }
  };
  share_out(threads_, {}, parts_, one, 1);
}

template <bool kWithJacobian>
bool NormalEquations::run(const FactorGraph& graph, const Values& values, double* error,
                          std::string* reason) {
  if (!matches(graph, values)) {
    throw std::logic_error("NormalEquations used with a graph or Values of another structure");
  }
  const double* base = values.vector().data();
  const auto t0 = std::chrono::steady_clock::now();
  const bool parallel = evaluate_in_parallel<kWithJacobian>(graph, base);
  if (kWithJacobian && !parallel) {  // a shared evaluation's scatter zeroes its own parts
    std::fill(h_.begin(), h_.end(), 0.0);
    g_.setZero();
  }
  Workspace& ws = workspace(0);
  double total = 0;
  for (size_t fi = 0; fi < factors_.size(); ++fi) {
    const Factor& f = *graph[factors_[fi].slot];
    Outcome o;
    if (parallel) {
      o = outcomes_[fi];
    } else {
      // A linearization of a long trajectory is most of a solver iteration: a shutdown asked
      // for meanwhile must not wait for its end.
      if (fi % kFactorsPerCancellationCheck == kFactorsPerCancellationCheck - 1) {
        throw_if_cancelled();
      }
      o = evaluate<kWithJacobian>(fi, graph, base, ws, ws.JtJ.data(), ws.JtJ.outerStride(),
                                  ws.Jtr.data());
    }
    if (o.non_finite != nullptr) {
      if (reason) {
        *reason = "factor " + std::to_string(factors_[fi].slot) + " (" + f.name() +
                  ") has a non-finite " + o.non_finite;
      }
      return false;
    }
    total += o.half_squared;
    if (!parallel && o.jtj != nullptr) add(fi, f, o, 0, n_);
  }
  if (kWithJacobian && parallel) add_in_parallel(graph);
  if (threads_ > 1) {
    choice_[kWithJacobian].record(
        parallel, factors_.size(),
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  *error = total;
  return true;
}

bool NormalEquations::linearize(const FactorGraph& graph, const Values& values, double* error,
                                std::string* reason) {
  return run<true>(graph, values, error, reason);
}

bool NormalEquations::evaluate_error(const FactorGraph& graph, const Values& values, double* error,
                                     std::string* reason) {
  return run<false>(graph, values, error, reason);
}

void NormalEquations::multiply(const Eigen::Ref<const Eigen::VectorXd>& v,
                               Eigen::Ref<Eigen::VectorXd> out) const {
  out.setZero();
  for (int c = 0; c < n_; ++c) {
    for (int p = col_ptr_[c]; p < col_ptr_[c + 1]; ++p) {
      const int r = row_idx_[p];
      out[r] += h_[p] * v[c];
      if (r != c) out[c] += h_[p] * v[r];
    }
  }
}

void NormalEquations::add_step(const Eigen::Ref<const Eigen::VectorXd>& step,
                               Eigen::Ref<Eigen::VectorXd> x) const {
  for (size_t k = 0; k < var_slot_.size(); ++k) {
    x.segment(var_value_offset_[k], var_dim_[k]) += step.segment(var_col_[k], var_dim_[k]);
  }
}

Key NormalEquations::key_of_column(int col, const Values& values) const {
  const auto it = std::upper_bound(var_col_.begin(), var_col_.end(), col);
  return values.key(var_slot_[static_cast<size_t>(it - var_col_.begin()) - 1]);
}

}  // namespace kinograph::graph

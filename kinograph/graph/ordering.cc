#include "kinograph/graph/ordering.h"

#include <amd.h>
#include <ccolamd.h>
#include <cholmod.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace kinograph::graph {

std::string to_string(OrderingMethod method) {
  switch (method) {
    case OrderingMethod::kNatural:
      return "natural";
    case OrderingMethod::kAmd:
      return "amd";
    case OrderingMethod::kColamd:
      return "colamd";
    case OrderingMethod::kMetis:
      return "metis";
  }
  return "unknown";
}

namespace {

// Upper-triangle pattern (compressed columns, sorted, no diagonal) of the variable adjacency
// graph: two variables are adjacent when a factor touches both.
void adjacency(int n, const std::vector<std::vector<int>>& factor_variables,
               std::vector<int>& col_ptr, std::vector<int>& row_idx) {
  std::vector<std::vector<int>> cols(n);
  for (const auto& vars : factor_variables) {
    for (int a : vars) {
      for (int b : vars) {
        if (a < b) cols[b].push_back(a);
      }
    }
  }
  col_ptr.assign(n + 1, 0);
  row_idx.clear();
  for (int c = 0; c < n; ++c) {
    auto& rows = cols[c];
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    row_idx.insert(row_idx.end(), rows.begin(), rows.end());
    col_ptr[c + 1] = static_cast<int>(row_idx.size());
  }
}

std::vector<int> amd(int n, const std::vector<std::vector<int>>& factor_variables) {
  std::vector<int> col_ptr, row_idx;
  adjacency(n, factor_variables, col_ptr, row_idx);
  std::vector<int> perm(n);
  if (row_idx.empty()) {  // no edges: any order is perfect (and AMD rejects an empty pattern)
    std::iota(perm.begin(), perm.end(), 0);
    return perm;
  }
  double control[AMD_CONTROL], info[AMD_INFO];
  amd_defaults(control);
  const int status = amd_order(n, col_ptr.data(), row_idx.data(), perm.data(), control, info);
  if (status != AMD_OK && status != AMD_OK_BUT_JUMBLED) {
    throw std::runtime_error("AMD ordering failed with status " + std::to_string(status));
  }
  return perm;
}

std::vector<int> colamd(int n, const std::vector<std::vector<int>>& factor_variables,
                        const std::vector<int>& groups) {
  // Incidence matrix: one row per factor, one column per variable.
  std::vector<std::vector<int>> cols(n);
  int n_rows = 0;
  for (const auto& vars : factor_variables) {
    if (vars.empty()) continue;
    for (int v : vars) cols[v].push_back(n_rows);
    ++n_rows;
  }
  int nnz = 0;
  for (const auto& c : cols) nnz += static_cast<int>(c.size());
  const size_t alen = ccolamd_recommended(nnz, n_rows, n);
  if (alen == 0) throw std::runtime_error("CCOLAMD: bad problem size");
  std::vector<int> A(alen), p(n + 1);
  int pos = 0;
  for (int c = 0; c < n; ++c) {
    p[c] = pos;
    for (int r : cols[c]) A[pos++] = r;
  }
  p[n] = pos;
  double knobs[CCOLAMD_KNOBS];
  int stats[CCOLAMD_STATS];
  ccolamd_set_defaults(knobs);
  std::vector<int> cmember;
  if (!groups.empty()) {
    if (static_cast<int>(groups.size()) != n) {
      throw std::invalid_argument("compute_ordering: groups has " + std::to_string(groups.size()) +
                                  " entries for " + std::to_string(n) + " variables");
    }
    cmember = groups;
  }
  if (!ccolamd(n_rows, n, static_cast<int>(alen), A.data(), p.data(), knobs, stats,
               cmember.empty() ? nullptr : cmember.data())) {
    throw std::runtime_error("CCOLAMD ordering failed with status " +
                             std::to_string(stats[CCOLAMD_STATUS]));
  }
  return {p.begin(), p.begin() + n};
}

std::vector<int> metis(int n, const std::vector<std::vector<int>>& factor_variables) {
  std::vector<int> col_ptr, row_idx;
  adjacency(n, factor_variables, col_ptr, row_idx);
  if (row_idx.empty()) {  // no edges: any order is perfect, and METIS dislikes empty graphs
    std::vector<int> perm(n);
    std::iota(perm.begin(), perm.end(), 0);
    return perm;
  }
  cholmod_common common;
  cholmod_start(&common);
  common.print = 0;
  cholmod_sparse* A =
      cholmod_allocate_sparse(n, n, row_idx.size(), 1, 1, 1, CHOLMOD_PATTERN, &common);
  std::copy(col_ptr.begin(), col_ptr.end(), static_cast<int*>(A->p));
  std::copy(row_idx.begin(), row_idx.end(), static_cast<int*>(A->i));
  std::vector<int> perm(n);
  const int ok = cholmod_metis(A, nullptr, 0, 1, perm.data(), &common);
  cholmod_free_sparse(&A, &common);
  cholmod_finish(&common);
  if (!ok) throw std::runtime_error("METIS ordering failed");
  return perm;
}

}  // namespace

std::vector<int> compute_ordering(int num_variables,
                                  const std::vector<std::vector<int>>& factor_variables,
                                  OrderingMethod method, const std::vector<int>& groups) {
  for (const auto& vars : factor_variables) {
    for (int v : vars) {
      if (v < 0 || v >= num_variables) {
        throw std::invalid_argument("compute_ordering: variable " + std::to_string(v) +
                                    " out of range");
      }
    }
  }
  if (num_variables == 0) return {};
  switch (method) {
    case OrderingMethod::kNatural: {
      std::vector<int> perm(num_variables);
      std::iota(perm.begin(), perm.end(), 0);
      return perm;
    }
    case OrderingMethod::kAmd:
      return amd(num_variables, factor_variables);
    case OrderingMethod::kColamd:
      return colamd(num_variables, factor_variables, groups);
    case OrderingMethod::kMetis:
      return metis(num_variables, factor_variables);
  }
  throw std::invalid_argument("compute_ordering: unknown method");
}

}  // namespace kinograph::graph

#pragma once
// Fill-reducing elimination orderings of graph variables, computed on the variable level (one
// node per variable, not per scalar), shared by the batch solvers and ISAM2.
#include <string>
#include <vector>

namespace kinograph::graph {

/// How to order variables for elimination. All give the same solution; they differ in fill.
enum class OrderingMethod {
  kNatural,  ///< slot order of Values
  kAmd,      ///< approximate minimum degree on the variable adjacency graph (SuiteSparse AMD)
  kColamd,   ///< column AMD on the factor×variable incidence (SuiteSparse CCOLAMD), as GTSAM
  kMetis,    ///< nested dissection (METIS through CHOLMOD)
};

/// "natural", "amd", "colamd" or "metis".
std::string to_string(OrderingMethod method);

/// An elimination order: order[k] is the variable eliminated k-th. `factor_variables[f]` lists
/// the variables (0..num_variables-1) that factor f touches. With kColamd, `groups` (one entry
/// per variable, or empty) constrains the order: variables of a lower group come first, e.g.
/// ISAM2 puts recently touched variables in the last group. Other methods ignore `groups`.
std::vector<int> compute_ordering(int num_variables,
                                  const std::vector<std::vector<int>>& factor_variables,
                                  OrderingMethod method, const std::vector<int>& groups = {});

}  // namespace kinograph::graph

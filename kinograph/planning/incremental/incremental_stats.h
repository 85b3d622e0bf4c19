#pragma once
// What an incremental plan or replan did, beside its Plan::stats.
#include <string>

namespace kinograph::planning {

/// What the last plan or replan did; complements Plan::stats.
struct IncrementalStats {
  std::string method;        ///< "batch-L"/"batch-W" (first or warm plan) or "incremental"
  int updates = 0;           ///< ISAM2 updates
  int rounds = 0;            ///< multiplier rounds (each re-adds the factors it changed)
  int factors_replaced = 0;  ///< factors removed for the change itself
  int factors_added = 0;     ///< factors added for the change itself
  int factors_readded = 0;   ///< factors re-added for multiplier or penalty changes
  long cliques_reeliminated = 0;   ///< cliques of the Bayes tree built by the updates
  /// Variables re-eliminated by the updates, in cliques or in a banded solve of the whole
  /// system (ISAM2Options::banded_full_updates), which builds no clique.
  long variables_reeliminated = 0;
  long variables_relinearized = 0;
  int full_reeliminations = 0;     ///< updates that re-eliminated every variable
  double incremental_time_s = 0;  ///< the ISAM2 part (whole replan time is in Plan::stats)
  double penalty = 0;             ///< μ at the end
};

}  // namespace kinograph::planning

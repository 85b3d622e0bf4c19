#pragma once
// The incremental planner's solver state: the planning graph's factor table in its incremental
// form, the ISAM2 Bayes tree over it, the constraint multipliers beside it, and the factor
// changes waiting for the next ISAM2 update.
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "kinograph/graph/isam2.h"
#include "kinograph/planning/formulation/planning_graph.h"
#include "kinograph/planning/incremental/incremental_stats.h"
#include "kinograph/planning/solver/constraint_state.h"

namespace kinograph::planning {

/// The Bayes tree of a planning graph and the table of its factors (slots are ISAM2 indices).
struct IncrementalTree {
  explicit IncrementalTree(graph::ISAM2Options options) : isam2_options(options) {}

  graph::ISAM2Options isam2_options;
  std::unique_ptr<graph::ISAM2> isam;
  std::vector<FactorEntry> entries;  ///< live factors
  std::map<int, std::shared_ptr<CollisionContext>> contexts;  ///< collision world per obstacle
  std::shared_ptr<DynamicsWorkspace> workspace;
  ConstraintState constraints;
  double last_violation = -1;  ///< worst scaled violation at the last multiplier round

  /// A fresh Bayes tree of every entry at `values` (one full elimination; variables no entry
  /// uses are left out); nothing pending.
  graph::ISAM2Result build(const graph::Values& values);
  /// Renames every variable of the tree and of the entries waiting to be added
  /// (ISAM2::rename_variables).
  void rename(const std::function<graph::Key(graph::Key)>& rename);
  /// Variables to add at the next update.
  void queue_values(const graph::Values& values);
  /// Variables whose factors have all been removed (a trajectory's states left behind): each is
  /// held at its estimate by a unit prior so that the eliminated system stays regular, until the
  /// next fresh tree leaves them out. Queued for the next update.
  void retire(const std::vector<graph::Key>& keys);
  /// Queues entry `i`'s factor to be added at the next update (its old slot, if any, is queued
  /// apart). Entries may be reordered or dropped meanwhile: a factor no entry holds any more is
  /// not added.
  void queue_add(size_t i) { pending_add_.push_back(entries[i].factor); }
  /// The entries become `keep` then `added` (queued, their constraint rows bound to the records
  /// under their keys), and `removed_slots` are queued to be emptied.
  void replace(std::vector<FactorEntry> keep, std::vector<FactorEntry> added,
               const std::vector<size_t>& removed_slots);
  /// Queues an ISAM2 slot to be emptied at the next update (once, however often queued).
  void queue_remove(size_t slot) { pending_remove_.push_back(slot); }
  /// A fresh tree from the current estimate at the next update when re-added factors left
  /// many empty slots in the ISAM2 graph, or retired variables outnumber the live ones.
  void compact_if_sparse();
  /// One ISAM2 update with the queued changes; its counts and time add to `stats`.
  graph::ISAM2Result update(bool force_relinearize, IncrementalStats& stats);

  /// Relinearizes the tree at its estimate with the start's and goal's variables ordered near
  /// the root (ISAM2::relinearize_at_estimate); nothing (nullopt) while a change is queued.
  std::optional<graph::ISAM2Result> relinearize_at_estimate();

  /// The soft cost (and the worst violation) of the ISAM2 graph at its estimate, in slot order.
  double soft_cost(double* violation = nullptr) const;

  /// The estimate and the constraint state, to return to when a replan's result is dropped.
  struct Snapshot {
    graph::Values values;
    ConstraintState::Snapshot constraints;
  };
  Snapshot snapshot() const { return {isam->estimate(), constraints.snapshot()}; }
  /// A fresh tree at the snapshot; false when it cannot be built.
  bool restore(const Snapshot& s);

 private:
  std::vector<graph::FactorPtr> pending_add_;  // entries' factors to add
  std::vector<graph::FactorPtr> pending_priors_;  // priors of retired variables, to add
  int retired_ = 0;                     // retired variables in the ISAM2 tree
  std::vector<size_t> pending_remove_;  // ISAM2 slots to empty
  graph::Values pending_values_;        // only when the tree is (re)built
};

}  // namespace kinograph::planning

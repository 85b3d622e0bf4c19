#include "kinograph/planning/incremental/incremental_tree.h"

#include <algorithm>

namespace kinograph::planning {
namespace {
// The tree is rebuilt (one full elimination) when the ISAM2 graph holds more than this many
// slots per live factor: every multiplier round re-adds factors and leaves their old slots
// empty, and elimination walks all slots.
constexpr double kCompactionRatio = 4.0;
}  // namespace

graph::ISAM2Result IncrementalTree::build(const graph::Values& values) {
  isam = std::make_unique<graph::ISAM2>(isam2_options);
  std::vector<graph::FactorPtr> all;
  all.reserve(entries.size());
  for (const FactorEntry& e : entries) all.push_back(e.factor);
  const graph::ISAM2Result r = isam->update(all, {}, values);
  for (size_t i = 0; i < entries.size(); ++i) entries[i].slot = r.new_factor_indices[i];
  pending_values_ = graph::Values();
  pending_remove_.clear();
  pending_add_.clear();
  return r;
}

void IncrementalTree::compact_if_sparse() {
  if (static_cast<double>(isam->graph().size()) <=
      kCompactionRatio * static_cast<double>(entries.size())) {
    return;
  }
  pending_values_ = isam->estimate();
  isam = std::make_unique<graph::ISAM2>(isam2_options);
  pending_remove_.clear();
  pending_add_.clear();
  for (size_t i = 0; i < entries.size(); ++i) pending_add_.push_back(i);
}

graph::ISAM2Result IncrementalTree::update(bool force_relinearize, IncrementalStats& stats) {
  std::vector<graph::FactorPtr> new_factors;
  for (size_t i : pending_add_) new_factors.push_back(entries[i].factor);
  graph::ISAM2UpdateOptions uo;
  uo.force_relinearize = force_relinearize;
  const graph::ISAM2Result r = isam->update(new_factors, pending_remove_, pending_values_, uo);
  for (size_t i = 0; i < pending_add_.size(); ++i) {
    entries[pending_add_[i]].slot = r.new_factor_indices[i];
  }
  pending_add_.clear();
  pending_remove_.clear();
  pending_values_ = graph::Values();
  ++stats.updates;
  stats.cliques_reeliminated += r.cliques_reeliminated;
  stats.variables_relinearized += r.variables_relinearized;
  stats.full_reeliminations += r.full_reelimination ? 1 : 0;
  return r;
}

double IncrementalTree::soft_cost(double* violation) const {
  // Slot order, as the ISAM2 graph sums its error: the stopping rule compares these costs.
  std::vector<const FactorEntry*> by_slot(isam->graph().size(), nullptr);
  for (const FactorEntry& e : entries) by_slot[e.slot] = &e;
  std::erase(by_slot, nullptr);
  return planning::soft_cost(by_slot, isam->estimate(), violation);
}

bool IncrementalTree::restore(const Snapshot& s) {
  constraints.restore(s.constraints);
  return build(s.values).ok();
}

}  // namespace kinograph::planning

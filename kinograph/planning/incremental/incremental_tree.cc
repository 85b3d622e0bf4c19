#include "kinograph/planning/incremental/incremental_tree.h"

#include <algorithm>
#include <unordered_map>
#include <unordered_set>

#include "kinograph/graph/prior_factor.h"

namespace kinograph::planning {
namespace {
// The tree is rebuilt (one full elimination) when the ISAM2 graph holds more than this many
// slots per live factor: every multiplier round re-adds factors and leaves their old slots
// empty, and elimination walks all slots.
constexpr double kCompactionRatio = 4.0;

// The variables of `values` that the entries use, with their fixed flags.
graph::Values used_values(const std::vector<FactorEntry>& entries, const graph::Values& values) {
  std::unordered_set<graph::Key> used;
  for (const FactorEntry& e : entries) used.insert(e.factor->keys().begin(), e.factor->keys().end());
  const auto is_used = [&used](graph::Key k) { return used.count(k) > 0; };
  if (std::all_of(values.keys().begin(), values.keys().end(), is_used)) return values;
  graph::Values out;
  for (int s = 0; s < values.size(); ++s) {
    const graph::Key k = values.key(s);
    if (used.count(k) == 0) continue;
    out.insert(k, values.at_slot(s));
    if (values.is_fixed_slot(s)) out.set_fixed(k);
  }
  return out;
}

}  // namespace

graph::ISAM2Result IncrementalTree::build(const graph::Values& values) {
  isam = std::make_unique<graph::ISAM2>(isam2_options);
  std::vector<graph::FactorPtr> all;
  all.reserve(entries.size());
  for (const FactorEntry& e : entries) all.push_back(e.factor);
  const graph::ISAM2Result r = isam->update(all, {}, used_values(entries, values));
  retired_ = 0;
  pending_priors_.clear();
  for (size_t i = 0; i < entries.size(); ++i) entries[i].slot = r.new_factor_indices[i];
  pending_values_ = graph::Values();
  pending_remove_.clear();
  pending_add_.clear();
  return r;
}

void IncrementalTree::compact_if_sparse() {
  const int live = isam->estimate().size() - retired_;
  if (static_cast<double>(isam->graph().size()) <=
          kCompactionRatio * static_cast<double>(entries.size()) &&
      retired_ <= live) {
    return;
  }
  graph::Values values = isam->estimate();
  for (int s = 0; s < pending_values_.size(); ++s) {
    values.insert(pending_values_.key(s), pending_values_.at_slot(s));
    if (pending_values_.is_fixed_slot(s)) values.set_fixed(pending_values_.key(s));
  }
  pending_values_ = used_values(entries, values);
  isam = std::make_unique<graph::ISAM2>(isam2_options);
  pending_remove_.clear();
  pending_add_.clear();
  pending_priors_.clear();
  retired_ = 0;
  for (size_t i = 0; i < entries.size(); ++i) queue_add(i);
}

void IncrementalTree::replace(std::vector<FactorEntry> keep, std::vector<FactorEntry> added,
                              const std::vector<size_t>& removed_slots) {
  for (const FactorEntry& e : added) {
    if (e.constrained && e.constrained->has_constraints()) constraints.bind(e);
  }
  entries = std::move(keep);
  for (size_t slot : removed_slots) queue_remove(slot);
  for (FactorEntry& e : added) {
    entries.push_back(std::move(e));
    queue_add(entries.size() - 1);
  }
}

void IncrementalTree::rename(const std::function<graph::Key(graph::Key)>& rename) {
  std::unordered_set<const graph::Factor*> renamed;
  for (size_t i = 0; i < isam->graph().size(); ++i) {
    if (isam->graph()[i]) renamed.insert(isam->graph()[i].get());
  }
  isam->rename_variables(rename);
  for (const FactorEntry& e : entries) {
    if (renamed.insert(e.factor.get()).second) e.factor->rename_keys(rename);
  }
  for (const graph::FactorPtr& f : pending_priors_) f->rename_keys(rename);
  pending_values_.rename(rename);
}

void IncrementalTree::queue_values(const graph::Values& values) {
  for (int s = 0; s < values.size(); ++s) {
    pending_values_.insert(values.key(s), values.at_slot(s));
    if (values.is_fixed_slot(s)) pending_values_.set_fixed(values.key(s));
  }
}

void IncrementalTree::retire(const std::vector<graph::Key>& keys) {
  const graph::Values& estimate = isam->estimate();
  for (const graph::Key& k : keys) {
    if (estimate.is_fixed(k)) continue;  // a fixed variable is no part of the eliminated system
    pending_priors_.push_back(std::make_shared<graph::PriorFactor>(k, estimate.at(k)));
    ++retired_;
  }
}

graph::ISAM2Result IncrementalTree::update(bool force_relinearize, IncrementalStats& stats) {
  std::unordered_map<const graph::Factor*, size_t> entry_of;
  if (!pending_add_.empty()) {
    for (size_t i = 0; i < entries.size(); ++i) entry_of.emplace(entries[i].factor.get(), i);
  }
  std::vector<size_t> added;  // entries, each once
  std::unordered_set<size_t> seen;
  for (const graph::FactorPtr& f : pending_add_) {
    const auto it = entry_of.find(f.get());
    if (it != entry_of.end() && seen.insert(it->second).second) added.push_back(it->second);
  }
  std::vector<graph::FactorPtr> new_factors;
  for (size_t i : added) new_factors.push_back(entries[i].factor);
  new_factors.insert(new_factors.end(), pending_priors_.begin(), pending_priors_.end());
  std::sort(pending_remove_.begin(), pending_remove_.end());
  pending_remove_.erase(std::unique(pending_remove_.begin(), pending_remove_.end()),
                        pending_remove_.end());
  graph::ISAM2UpdateOptions uo;
  uo.force_relinearize = force_relinearize;
  const graph::ISAM2Result r = isam->update(new_factors, pending_remove_, pending_values_, uo);
  for (size_t i = 0; i < added.size(); ++i) entries[added[i]].slot = r.new_factor_indices[i];
  pending_add_.clear();
  pending_priors_.clear();
  pending_remove_.clear();
  pending_values_ = graph::Values();
  ++stats.updates;
  stats.cliques_reeliminated += r.cliques_reeliminated;
  stats.variables_reeliminated += r.variables_reeliminated;
  stats.variables_relinearized += r.variables_relinearized;
  stats.full_reeliminations += r.full_reelimination ? 1 : 0;
  return r;
}

std::optional<graph::ISAM2Result> IncrementalTree::relinearize_at_estimate() {
  if (!pending_add_.empty() || !pending_priors_.empty() || !pending_remove_.empty() ||
      pending_values_.size() > 0) {
    return std::nullopt;
  }
  // The variables a new goal or a new measured start changes: at the root, such a change
  // re-eliminates only the root.
  std::vector<graph::Key> last;
  for (const FactorEntry& e : entries) {
    if (e.key.role != FactorRole::kStart && e.key.role != FactorRole::kGoal) continue;
    for (const graph::Key& k : e.factor->keys()) {
      if (std::find(last.begin(), last.end(), k) == last.end()) last.push_back(k);
    }
  }
  return isam->relinearize_at_estimate(last);
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

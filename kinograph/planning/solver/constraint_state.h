#pragma once
// The augmented-Lagrangian state of a planning graph: one Multipliers record per constraint
// factor, kept beside the graph under the factor's FactorKey (the factors only read them), and
// the penalty μ common to all of them.
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "kinograph/planning/factors/constrained_factor.h"
#include "kinograph/planning/formulation/planning_graph.h"

namespace kinograph::planning {

/// Multipliers and penalty of a graph's constraint factors, keyed by FactorKey. A record
/// outlives its factor, so a replacement factor under the same key (a moved obstacle, a new
/// goal, a new Δt) starts from its predecessor's multipliers.
class ConstraintState {
 public:
  /// An empty state with penalty μ (> 0).
  explicit ConstraintState(double penalty = 1);

  /// Binds the entry's factor (one with constraint rows) to the record under its key: the kept
  /// one when its size matches the factor's rows, else a new record of zeros; either at the
  /// common μ.
  void bind(const FactorEntry& entry);
  /// Forgets the record under `key` (its factor left the graph without replacement).
  void erase(const FactorKey& key);
  /// Files every record under `rename(key)`, or forgets it when that is empty (its factor left
  /// the graph). Throws std::invalid_argument when two records would meet (nothing changed).
  void rename(const std::function<std::optional<FactorKey>(const FactorKey&)>& rename);
  bool contains(const FactorKey& key) const { return records_.count(key) > 0; }
  /// The record under `key`; throws std::out_of_range if there is none. After changing its
  /// multipliers, the factors that were linearized with the old ones must be re-linearized.
  Multipliers& at(const FactorKey& key);
  const Multipliers& at(const FactorKey& key) const;

  double penalty() const { return penalty_; }
  /// Sets μ on every record (and marks each bound factor's Jacobian changed).
  void set_penalty(double mu);

  /// The values of every record and μ.
  struct Snapshot {
    std::map<FactorKey, Multipliers> records;
    double penalty = 1;
  };
  Snapshot snapshot() const;
  /// Puts back a snapshot's values into the records it holds (the others are left as they are).
  void restore(const Snapshot& snapshot);

 private:
  struct Record {
    std::shared_ptr<Multipliers> m;
    std::weak_ptr<ConstrainedFactor> factor;  // the factor reading it
  };
  std::map<FactorKey, Record> records_;
  double penalty_;
};

}  // namespace kinograph::planning

#pragma once
// The set of factors of a problem. Factors are held by shared pointer and addressed by a stable
// index: removing a factor empties its slot and never renumbers the others (ISAM2 relies on it).
#include <cstdint>
#include <memory>
#include <vector>

#include "kinograph/graph/factor.h"

namespace kinograph::graph {

using FactorPtr = std::shared_ptr<Factor>;

/// A sum of factors ½Σ‖r_f(x)‖². Slots of removed factors stay empty (null).
class FactorGraph {
 public:
  /// Appends a factor and returns its index. Throws std::invalid_argument on null.
  size_t add(FactorPtr factor);
  /// Constructs and appends a factor of type F; returns a pointer to it.
  template <class F, class... Args>
  std::shared_ptr<F> emplace(Args&&... args) {
    auto f = std::make_shared<F>(std::forward<Args>(args)...);
    add(f);
    return f;
  }
  /// Empties slot i (no-op if already empty); throws std::out_of_range if i >= size().
  void remove(size_t i);

  /// Number of slots, including empty ones.
  size_t size() const { return factors_.size(); }
  /// Number of non-empty slots.
  size_t num_factors() const { return count_; }
  /// Factor in slot i, or null if removed.
  const FactorPtr& at(size_t i) const { return factors_[i]; }
  const FactorPtr& operator[](size_t i) const { return factors_[i]; }
  const std::vector<FactorPtr>& factors() const { return factors_; }

  /// Total cost ½Σ‖r_f‖² at `values`.
  double error(const Values& values) const;

  /// Identifies the structure (which factors are in which slots). Adding or removing a factor
  /// gives a new process-unique id; solvers cache their symbolic analysis against it.
  uint64_t structure_id() const { return structure_id_; }

 private:
  std::vector<FactorPtr> factors_;
  size_t count_ = 0;
  uint64_t structure_id_ = 0;
};

}  // namespace kinograph::graph

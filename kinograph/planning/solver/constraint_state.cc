#include "kinograph/planning/solver/constraint_state.h"

#include <stdexcept>

namespace kinograph::planning {

ConstraintState::ConstraintState(double penalty) : penalty_(penalty) {
  if (!(penalty > 0)) throw std::invalid_argument("ConstraintState: penalty must be positive");
}

void ConstraintState::bind(const FactorEntry& entry) {
  const std::shared_ptr<ConstrainedFactor>& f = entry.constrained;
  if (!f) throw std::invalid_argument("ConstraintState: the entry has no constraint factor");
  Record& r = records_[entry.key];
  if (!r.m || r.m->lower.size() != f->residual_dim()) {
    r.m = std::make_shared<Multipliers>(f->residual_dim(), penalty_);
  }
  r.m->penalty = penalty_;
  r.factor = f;
  f->bind(r.m);
}

void ConstraintState::erase(const FactorKey& key) { records_.erase(key); }

void ConstraintState::rename(
    const std::function<std::optional<FactorKey>(const FactorKey&)>& rename) {
  std::map<FactorKey, Record> renamed;
  for (const auto& [key, record] : records_) {
    const std::optional<FactorKey> to = rename(key);
    if (to && !renamed.emplace(*to, record).second) {
      throw std::invalid_argument("ConstraintState::rename: two records would meet");
    }
  }
  records_ = std::move(renamed);
}

Multipliers& ConstraintState::at(const FactorKey& key) { return *records_.at(key).m; }

const Multipliers& ConstraintState::at(const FactorKey& key) const {
  return *records_.at(key).m;
}

void ConstraintState::set_penalty(double mu) {
  if (!(mu > 0)) throw std::invalid_argument("ConstraintState: penalty must be positive");
  penalty_ = mu;
  for (auto& [key, r] : records_) {
    r.m->penalty = mu;
    if (auto f = r.factor.lock()) f->penalty_changed();
  }
}

ConstraintState::Snapshot ConstraintState::snapshot() const {
  Snapshot s;
  s.penalty = penalty_;
  for (const auto& [key, r] : records_) s.records.emplace(key, *r.m);
  return s;
}

void ConstraintState::restore(const Snapshot& s) {
  penalty_ = s.penalty;
  for (const auto& [key, m] : s.records) {
    const auto it = records_.find(key);
    if (it == records_.end() || it->second.m->lower.size() != m.lower.size()) continue;
    *it->second.m = m;
    if (auto f = it->second.factor.lock()) f->penalty_changed();
  }
}

}  // namespace kinograph::planning

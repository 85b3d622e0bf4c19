#include "kinograph/graph/values.h"

#include <atomic>
#include <stdexcept>

namespace kinograph::graph {

namespace {
std::atomic<uint64_t> g_next_layout{1};
}

void Values::new_layout() { layout_id_ = g_next_layout.fetch_add(1); }

void Values::insert(Key key, const Eigen::Ref<const Eigen::VectorXd>& value) {
  if (value.size() == 0) {
    throw std::invalid_argument("Values::insert: empty vector for " + key.to_string());
  }
  if (!slot_of_.emplace(key, size()).second) {
    throw std::invalid_argument("Values::insert: " + key.to_string() + " already exists");
  }
  const int offset = total_dim();
  keys_.push_back(key);
  offsets_.push_back(offset);
  dims_.push_back(static_cast<int>(value.size()));
  fixed_.push_back(0);
  data_.conservativeResize(offset + value.size());
  data_.segment(offset, value.size()) = value;
  new_layout();
}

void Values::update(Key key, const Eigen::Ref<const Eigen::VectorXd>& value) {
  const int s = slot(key);
  if (value.size() != dims_[s]) {
    throw std::invalid_argument("Values::update: " + key.to_string() + " has dimension " +
                                std::to_string(dims_[s]) + ", got " + std::to_string(value.size()));
  }
  data_.segment(offsets_[s], dims_[s]) = value;
}

int Values::find(Key key) const {
  auto it = slot_of_.find(key);
  return it == slot_of_.end() ? -1 : it->second;
}

int Values::slot(Key key) const {
  auto it = slot_of_.find(key);
  if (it == slot_of_.end()) {
    throw std::out_of_range("Values: no variable " + key.to_string());
  }
  return it->second;
}

Eigen::Map<const Eigen::VectorXd> Values::at(Key key) const { return at_slot(slot(key)); }

Eigen::Map<Eigen::VectorXd> Values::at(Key key) { return at_slot(slot(key)); }

void Values::retract(const Eigen::Ref<const Eigen::VectorXd>& delta) {
  if (delta.size() != data_.size()) {
    throw std::invalid_argument("Values::retract: delta has size " + std::to_string(delta.size()) +
                                ", values " + std::to_string(data_.size()));
  }
  for (int s = 0; s < size(); ++s) {
    if (!fixed_[s]) data_.segment(offsets_[s], dims_[s]) += delta.segment(offsets_[s], dims_[s]);
  }
}

void Values::retract(Key key, const Eigen::Ref<const Eigen::VectorXd>& delta) {
  const int s = slot(key);
  if (delta.size() != dims_[s]) {
    throw std::invalid_argument("Values::retract: " + key.to_string() + " has dimension " +
                                std::to_string(dims_[s]));
  }
  if (!fixed_[s]) data_.segment(offsets_[s], dims_[s]) += delta;
}

void Values::rename(const std::function<Key(Key)>& rename) {
  std::vector<Key> keys(keys_.size());
  std::unordered_map<Key, int> slot_of;
  for (size_t s = 0; s < keys_.size(); ++s) {
    keys[s] = rename(keys_[s]);
    if (!slot_of.emplace(keys[s], static_cast<int>(s)).second) {
      throw std::invalid_argument("Values::rename: " + keys_[s].to_string() + " and another " +
                                  "variable would both be " + keys[s].to_string());
    }
  }
  keys_ = std::move(keys);
  slot_of_ = std::move(slot_of);
  new_layout();
}

void Values::set_fixed(Key key, bool fixed) {
  const int s = slot(key);
  if ((fixed_[s] != 0) != fixed) {
    fixed_[s] = fixed ? 1 : 0;
    new_layout();
  }
}

}  // namespace kinograph::graph

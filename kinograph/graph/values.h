#pragma once
// Current estimates of all graph variables, stored in one contiguous vector with an offset
// table, so that solvers update them with one vector addition and factors read them without
// copying.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <unordered_map>
#include <vector>

#include "kinograph/graph/key.h"

namespace kinograph::graph {

/// All variables of a problem (vectors of any fixed dimension), keyed by Key. Each variable
/// occupies a slot (its insertion rank) and a contiguous segment of vector(). A variable can be
/// marked fixed: solvers then treat it as a constant.
class Values {
 public:
  Values() = default;

  /// Adds a variable. Throws std::invalid_argument if the key exists or the vector is empty.
  void insert(Key key, const Eigen::Ref<const Eigen::VectorXd>& value);
  /// Overwrites an existing variable (same dimension); throws std::out_of_range /
  /// std::invalid_argument otherwise. Does not change the layout.
  void update(Key key, const Eigen::Ref<const Eigen::VectorXd>& value);

  bool contains(Key key) const { return slot_of_.count(key) != 0; }
  /// Slot of a variable, or -1 if absent.
  int find(Key key) const;
  /// Slot of a variable; throws std::out_of_range naming the key if absent.
  int slot(Key key) const;

  /// Number of variables.
  int size() const { return static_cast<int>(keys_.size()); }
  /// Total scalar dimension (length of vector()).
  int total_dim() const { return static_cast<int>(data_.size()); }

  Key key(int slot) const { return keys_[slot]; }
  int offset(int slot) const { return offsets_[slot]; }
  int dim(int slot) const { return dims_[slot]; }
  const std::vector<Key>& keys() const { return keys_; }

  /// The value of a variable, as a view into vector(); throws std::out_of_range if absent.
  Eigen::Map<const Eigen::VectorXd> at(Key key) const;
  Eigen::Map<Eigen::VectorXd> at(Key key);
  Eigen::Map<const Eigen::VectorXd> at_slot(int slot) const {
    return {data_.data() + offsets_[slot], dims_[slot]};
  }
  Eigen::Map<Eigen::VectorXd> at_slot(int slot) {
    return {data_.data() + offsets_[slot], dims_[slot]};
  }

  /// All variables stacked in slot order. Writing through it changes values, not layout.
  const Eigen::VectorXd& vector() const { return data_; }
  Eigen::VectorXd& vector() { return data_; }

  /// x ← x + delta for every non-fixed variable; delta is laid out like vector().
  void retract(const Eigen::Ref<const Eigen::VectorXd>& delta);
  /// x_key ← x_key + delta for one variable (ignored if the variable is fixed).
  void retract(Key key, const Eigen::Ref<const Eigen::VectorXd>& delta);

  /// Renames every variable (`rename` must keep distinct keys distinct); slots, values and
  /// fixed flags stay. Throws std::invalid_argument when two keys would merge (nothing changed).
  void rename(const std::function<Key(Key)>& rename);

  /// Marks a variable constant (or free again). Changes the layout id: solvers rebuild.
  void set_fixed(Key key, bool fixed = true);
  bool is_fixed(Key key) const { return fixed_[slot(key)] != 0; }
  bool is_fixed_slot(int slot) const { return fixed_[slot] != 0; }

  /// Identifies the layout (keys, dimensions, fixed flags). Any change of layout gives a new
  /// process-unique id; copies share it. Solvers cache their structure against it.
  uint64_t layout_id() const { return layout_id_; }

 private:
  void new_layout();

  Eigen::VectorXd data_;
  std::vector<Key> keys_;
  std::vector<int> offsets_;
  std::vector<int> dims_;
  std::vector<char> fixed_;
  std::unordered_map<Key, int> slot_of_;
  uint64_t layout_id_ = 0;
};

}  // namespace kinograph::graph

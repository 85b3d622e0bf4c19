#pragma once
// Names of graph variables: a kind (a letter such as 'q' for joint angles), an index (which
// joint, link or obstacle) and a time step, packed into one 64-bit integer.
#include <compare>
#include <cstdint>
#include <functional>
#include <string>

namespace kinograph::graph {

/// A variable's name (kind, index, step), packed as kind:8 | index:24 | step:32 bits so that
/// keys hash and compare as integers.
class Key {
 public:
  static constexpr uint32_t kMaxIndex = (1u << 24) - 1;

  constexpr Key() = default;
  /// Throws std::invalid_argument if index exceeds kMaxIndex.
  Key(char kind, uint32_t index, uint32_t step);
  /// Rebuilds a key from its packed form (as returned by id()).
  static constexpr Key from_id(uint64_t id) {
    Key k;
    k.id_ = id;
    return k;
  }

  constexpr char kind() const { return static_cast<char>(id_ >> 56); }
  constexpr uint32_t index() const { return static_cast<uint32_t>((id_ >> 32) & kMaxIndex); }
  constexpr uint32_t step() const { return static_cast<uint32_t>(id_ & 0xffffffffu); }
  constexpr uint64_t id() const { return id_; }

  /// Human-readable form "kind(index,step)", e.g. "q(1,15)", used in error messages.
  std::string to_string() const;

  constexpr auto operator<=>(const Key&) const = default;

 private:
  uint64_t id_ = 0;
};

}  // namespace kinograph::graph

/// @cond
// Doxygen cannot place a specialization of std's template: left out of the reference.
template <>
struct std::hash<kinograph::graph::Key> {
  size_t operator()(const kinograph::graph::Key& k) const noexcept {
    return std::hash<uint64_t>{}(k.id());
  }
};
/// @endcond

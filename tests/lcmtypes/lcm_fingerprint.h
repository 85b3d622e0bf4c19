#pragma once
// LCM's type fingerprint computed from a type's member list, following the rule LCM documents
// for lcm-gen (lcmgen/doc.txt and lcm-type-ref, "fingerprint"), independently of lcm-gen's
// output: a base hash over each member's name, primitive type name and array dimensions (not
// the struct's own name, nor a nested struct's name), plus the fingerprints of nested structs,
// rotated left by one bit at each level. Tests use it to check that a .lcm file written here
// has the fingerprint of the layout it claims to match.
#include <cstdint>
#include <string>
#include <vector>

namespace kinograph::lcmtypes::testing {

struct StructSpec;

/// One array dimension: a constant size ("3") or the name of a count member ("num_joints").
struct Dimension {
  bool variable = false;
  std::string size;
};

/// One member: a primitive (type = "int64_t", "double", "string", ...) or a nested struct.
struct MemberSpec {
  std::string name;
  std::string type;                    ///< primitive type name; empty for a nested struct
  const StructSpec* nested = nullptr;  ///< the nested struct's spec when type is empty
  std::vector<Dimension> dims;
};

/// A struct's members in declaration order (constants are not members).
struct StructSpec {
  std::vector<MemberSpec> members;
};

namespace detail {

// v = ((v << 8) ^ (v >> 55)) + c on signed 64-bit integers, with c a signed char (the C rule).
inline int64_t hash_update(int64_t v, int c) {
  const uint64_t shifted = static_cast<uint64_t>(v) << 8;
  const uint64_t sign_fill = static_cast<uint64_t>(v >> 55);  // arithmetic shift, as C on int64
  return static_cast<int64_t>((shifted ^ sign_fill) + static_cast<uint64_t>(static_cast<int64_t>(
                                                          static_cast<signed char>(c))));
}

inline int64_t hash_string(int64_t v, const std::string& s) {
  v = hash_update(v, static_cast<int>(s.size()));
  for (const char c : s) v = hash_update(v, c);
  return v;
}

inline uint64_t rotate_left_1(uint64_t v) { return (v << 1) + ((v >> 63) & 1); }

inline uint64_t fingerprint(const StructSpec& s, std::vector<const StructSpec*>& parents);

}  // namespace detail

/// The base hash K of a struct: 0x12345678 updated by every member's name, its type name when
/// primitive, its number of dimensions and each dimension's mode (0 constant, 1 variable) and
/// size text.
inline int64_t base_hash(const StructSpec& s) {
  int64_t v = 0x12345678;
  for (const MemberSpec& m : s.members) {
    v = detail::hash_string(v, m.name);
    if (m.nested == nullptr) v = detail::hash_string(v, m.type);
    v = detail::hash_update(v, static_cast<int>(m.dims.size()));
    for (const Dimension& d : m.dims) {
      v = detail::hash_update(v, d.variable ? 1 : 0);
      v = detail::hash_string(v, d.size);
    }
  }
  return v;
}

namespace detail {
inline uint64_t fingerprint(const StructSpec& s, std::vector<const StructSpec*>& parents) {
  for (const StructSpec* p : parents)
    if (p == &s) return 0;  // a type already on the path contributes nothing (recursion)
  parents.push_back(&s);
  uint64_t v = static_cast<uint64_t>(base_hash(s));
  for (const MemberSpec& m : s.members)
    if (m.nested != nullptr) v += fingerprint(*m.nested, parents);
  parents.pop_back();
  return rotate_left_1(v);
}
}  // namespace detail

/// The fingerprint LCM writes before every encoded message of this type (getHash()).
inline int64_t fingerprint(const StructSpec& s) {
  std::vector<const StructSpec*> parents;
  return static_cast<int64_t>(detail::fingerprint(s, parents));
}

/// A primitive member, scalar or with the given dimensions.
inline MemberSpec member(std::string name, std::string type, std::vector<Dimension> dims = {}) {
  return {std::move(name), std::move(type), nullptr, std::move(dims)};
}
/// A nested-struct member.
inline MemberSpec nested(std::string name, const StructSpec& type, std::vector<Dimension> dims) {
  return {std::move(name), "", &type, std::move(dims)};
}
/// An array dimension sized by a count member, and one of constant size.
inline Dimension var(std::string count) { return {true, std::move(count)}; }
inline Dimension fixed(int n) { return {false, std::to_string(n)}; }

}  // namespace kinograph::lcmtypes::testing

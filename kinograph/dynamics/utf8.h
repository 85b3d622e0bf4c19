#pragma once
// Whether a text read from a file is well-formed UTF-8, for the readers of URDF and YAML files:
// TinyXML (under urdfdom) steps over a multi-byte character by its lead byte alone and reads
// past the end of a text that ends inside one, and YAML text must be UTF-8 to be written back.
#include <cstddef>
#include <optional>
#include <string_view>

namespace kinograph::dynamics {

/// Where the first byte that does not belong to a well-formed UTF-8 character is (a stray
/// continuation byte, a truncated or overlong sequence, a surrogate, a code point past
/// U+10FFFF), or nullopt when `text` is UTF-8.
std::optional<std::size_t> first_invalid_utf8(std::string_view text);

/// 1-based line of byte `offset` of `text`.
int line_at(std::string_view text, std::size_t offset);

}  // namespace kinograph::dynamics

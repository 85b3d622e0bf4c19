#include "kinograph/dynamics/utf8.h"

#include <algorithm>

namespace kinograph::dynamics {

std::optional<std::size_t> first_invalid_utf8(std::string_view text) {
  const auto* begin = reinterpret_cast<const unsigned char*>(text.data());
  const auto* end = begin + text.size();
  for (const unsigned char* p = begin; p < end;) {
    const unsigned char* start = p;
    const unsigned c = *p++;
    if (c < 0x80) continue;
    // Continuation bytes that follow, and the smallest code point of that length.
    const int more = (c & 0xE0) == 0xC0 ? 1 : (c & 0xF0) == 0xE0 ? 2 : (c & 0xF8) == 0xF0 ? 3 : 0;
    if (more == 0 || end - p < more) return static_cast<std::size_t>(start - begin);
    const unsigned least = more == 1 ? 0x80 : more == 2 ? 0x800 : 0x10000;
    unsigned cp = c & (0x3F >> more);
    for (int k = 0; k < more; ++k) {
      if ((p[k] & 0xC0) != 0x80) return static_cast<std::size_t>(start - begin);
      cp = (cp << 6) | (p[k] & 0x3F);
    }
    if (cp < least || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) {
      return static_cast<std::size_t>(start - begin);
    }
    p += more;
  }
  return std::nullopt;
}

int line_at(std::string_view text, std::size_t offset) {
  const std::string_view before = text.substr(0, std::min(offset, text.size()));
  return 1 + static_cast<int>(std::count(before.begin(), before.end(), '\n'));
}

}  // namespace kinograph::dynamics

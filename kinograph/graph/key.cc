#include "kinograph/graph/key.h"

#include <stdexcept>

namespace kinograph::graph {

Key::Key(char kind, uint32_t index, uint32_t step) {
  if (index > kMaxIndex) {
    throw std::invalid_argument("Key index " + std::to_string(index) + " exceeds " +
                                std::to_string(kMaxIndex));
  }
  id_ = (static_cast<uint64_t>(static_cast<unsigned char>(kind)) << 56) |
        (static_cast<uint64_t>(index) << 32) | step;
}

std::string Key::to_string() const {
  std::string s;
  const char k = kind();
  if (k >= 32 && k < 127) {
    s += k;
  } else {
    s += '#';  // (appended in two steps: GCC 12 warns falsely on "#" + std::string)
    s += std::to_string(static_cast<unsigned char>(k));
  }
  return s + "(" + std::to_string(index()) + "," + std::to_string(step()) + ")";
}

}  // namespace kinograph::graph

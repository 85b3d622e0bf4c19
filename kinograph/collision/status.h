#pragma once

#include <string>

namespace kinograph::collision {

// Outcome of an operation that can fail in normal use (an unknown or duplicate obstacle id).
struct Status {
  bool ok = true;
  std::string reason;  // empty when ok

  static Status success() { return {}; }
  static Status failure(std::string why) { return {false, std::move(why)}; }
  explicit operator bool() const { return ok; }
};

}  // namespace kinograph::collision

#pragma once

#include <string>
#include <utility>

namespace kinograph::collision {

// Outcome of an operation that can fail in normal use (an unknown or duplicate obstacle id).
struct Status {
  bool ok = true;
  std::string reason;  // empty when ok

  // The operation did what was asked.
  static Status success() { return {}; }
  // The operation was refused, and why (e.g. "no obstacle with id 3").
  static Status failure(std::string why) { return {false, std::move(why)}; }
  // True when ok, so a Status can be tested directly.
  explicit operator bool() const { return ok; }
};

}  // namespace kinograph::collision

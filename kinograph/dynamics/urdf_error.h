#pragma once
// The one exception of the dynamics module: bad robot description input.
#include <stdexcept>
#include <string>

namespace kinograph::dynamics {

/// A URDF that cannot be used: missing/unreadable file, malformed XML, unsupported joint,
/// missing inertial on a moving link, mesh not found. The message names file and element.
class UrdfError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace kinograph::dynamics

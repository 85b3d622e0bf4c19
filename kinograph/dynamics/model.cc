#include "kinograph/dynamics/model.h"

#include <stdexcept>

namespace kinograph::dynamics {

int Model::frame_index(const std::string& frame_name) const {
  for (size_t i = 0; i < frames.size(); ++i) {
    if (frames[i].name == frame_name) return static_cast<int>(i);
  }
  throw std::out_of_range("model '" + name + "' has no frame '" + frame_name + "'");
}

int Model::body_index(const std::string& link) const {
  for (size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].name == link) return static_cast<int>(i);
  }
  throw std::out_of_range("model '" + name + "' has no moving body for link '" + link + "'");
}

double Model::total_mass() const {
  double m = 0;
  for (const Body& b : bodies) m += b.inertia(3, 3);
  return m;
}

}  // namespace kinograph::dynamics

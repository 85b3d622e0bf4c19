#include "kinograph/fleet/model_id.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <sstream>

namespace kinograph::fleet {
namespace {

// FNV-1a, 64 bit: a fixed function of the bytes, unlike std::hash.
class Fnv1a {
 public:
  void add(const std::string& text) {
    for (const unsigned char c : text) hash_ = (hash_ ^ c) * 1099511628211ull;
    hash_ = (hash_ ^ 0xff) * 1099511628211ull;  // field separator
  }
  // Numbers as text rounded to 1e-9, so that a last-bit difference of a parse does not count.
  void add(double value) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9f", std::isfinite(value) ? value : 0.0);
    add(std::isfinite(value) ? std::string(buf) : (value > 0 ? "inf" : "-inf"));
  }
  template <class Derived>
  void add(const Eigen::MatrixBase<Derived>& m) {
    const typename Derived::PlainObject values = m;
    for (Eigen::Index i = 0; i < values.size(); ++i) add(static_cast<double>(values.data()[i]));
  }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 14695981039346656037ull;
};

}  // namespace

std::string model_id(const dynamics::Model& model) {
  Fnv1a h;
  for (const dynamics::Body& b : model.bodies) {
    h.add(b.name);
    h.add(b.joint_name);
    h.add(static_cast<double>(b.parent));
    h.add(Eigen::Matrix4d(b.parent_to_joint.matrix()));
    h.add(b.screw_axis);
    h.add(b.limits.lower);
    h.add(b.limits.upper);
    h.add(b.limits.velocity);
    h.add(b.limits.effort);
  }
  for (const dynamics::Geometry& g : model.collision) {
    h.add(g.link_name);
    h.add(static_cast<double>(static_cast<int>(g.shape)));
    h.add(g.size);
    h.add(g.mesh_scale);
    h.add(Eigen::Matrix4d(g.origin.matrix()));
    h.add(static_cast<double>(g.body));
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h.value()));
  return model.name + ":" + hex;
}

std::string base_mismatch(const Eigen::Isometry3d& expected, const Eigen::Isometry3d& heard) {
  const double distance = (expected.translation() - heard.translation()).norm();
  const double angle =
      Eigen::AngleAxisd(expected.linear().transpose() * heard.linear()).angle();
  if (distance <= 1e-3 && angle <= 1e-3) return "";
  std::ostringstream os;
  os << "its base is " << distance << " m and " << angle
     << " rad from where the scene puts it (at [" << heard.translation().transpose()
     << "], expected [" << expected.translation().transpose() << "])";
  return os.str();
}

}  // namespace kinograph::fleet

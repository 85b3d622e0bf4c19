#include "kinograph/collision/capsule_bound.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace kinograph::collision {
namespace {

double point_segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

}  // namespace

CapsuleBound capsule_bound(const ConvexShape& shape) {
  const Eigen::Vector3d& sz = shape.shape().size;
  CapsuleBound c;
  switch (shape.shape().kind) {
    case ShapeKind::kCylinder:
    case ShapeKind::kCapsule:
      c.a = Eigen::Vector3d(0, 0, -sz.y() / 2);
      c.b = Eigen::Vector3d(0, 0, sz.y() / 2);
      c.radius = sz.x();
      return c;
    case ShapeKind::kBox: {
      int axis = 0;
      sz.maxCoeff(&axis);
      c.a[axis] = -sz[axis] / 2;
      c.b[axis] = sz[axis] / 2;
      // Every point of the box is within half the other two sides' diagonal of its long axis.
      c.radius = std::sqrt(sz.squaredNorm() - sz[axis] * sz[axis]) / 2;
      return c;
    }
    case ShapeKind::kSphere:
    case ShapeKind::kMesh:
      break;
  }
  c.a = c.b = shape.bound_center();
  c.radius = shape.bound_radius();
  return c;
}

CapsuleBound transformed(const Eigen::Isometry3d& pose, const CapsuleBound& c) {
  return CapsuleBound{pose * c.a, pose * c.b, c.radius};
}

CapsuleBound enclosing(std::span<const CapsuleBound> parts) {
  if (parts.empty()) return {};
  const CapsuleBound& axis = *std::max_element(
      parts.begin(), parts.end(), [](const CapsuleBound& x, const CapsuleBound& y) {
        return (x.b - x.a).squaredNorm() < (y.b - y.a).squaredNorm();
      });
  CapsuleBound out{axis.a, axis.b, 0};
  // The distance to a segment is convex, so a part's farthest point from the axis lies within
  // its radius of one of its own segment's ends.
  for (const CapsuleBound& p : parts) {
    out.radius = std::max(out.radius, std::max(point_segment_distance(p.a, axis.a, axis.b),
                                               point_segment_distance(p.b, axis.a, axis.b)) +
                                          p.radius);
  }
  return out;
}

double segment_distance(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                        const Eigen::Vector3d& q0, const Eigen::Vector3d& q1) {
  const Eigen::Vector3d d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  if (a <= 0 && e <= 0) return r.norm();
  if (a <= 0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return (p0 + s * d1 - (q0 + t * d2)).norm();
}

double lower_bound(const CapsuleBound& x, const CapsuleBound& y) {
  // The Minkowski difference of two segments is flat, so moving one capsule off it along the
  // normal separates them: the bound holds for penetration depth too.
  return segment_distance(x.a, x.b, y.a, y.b) - x.radius - y.radius;
}

double lower_bound(const CapsuleBound& x, const Eigen::Vector3d& centre, double radius) {
  return point_segment_distance(centre, x.a, x.b) - x.radius - radius;
}

double lower_bound(const CapsuleBound& x, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const Eigen::Vector3d slo = x.a.cwiseMin(x.b), shi = x.a.cwiseMax(x.b);
  const double gap = (lo - shi).cwiseMax(slo - hi).cwiseMax(0.0).norm();
  // Moving the capsule's box clear along the gap by radius − gap separates it: the bound holds
  // for penetration depth too, but only while the boxes are apart.
  if (!(gap > 0)) return -std::numeric_limits<double>::infinity();
  return gap - x.radius;
}

}  // namespace kinograph::collision

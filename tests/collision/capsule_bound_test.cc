// Bounding capsules: they contain their solids, the segment distance is the true minimum, and
// every lower bound stays at or below Bullet's signed distance, penetrating pairs included.
#include "kinograph/collision/capsule_bound.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "kinograph/collision/pair_distance.h"

namespace kinograph::collision {
namespace {

double point_segment(const Eigen::Vector3d& p, const CapsuleBound& c) {
  const Eigen::Vector3d ab = c.b - c.a;
  const double t =
      ab.squaredNorm() > 0 ? std::clamp((p - c.a).dot(ab) / ab.squaredNorm(), 0., 1.) : 0.0;
  return (c.a + t * ab - p).norm();
}

// A uniformly drawn point of the solid, in its own frame.
Eigen::Vector3d point_in(const Shape& s, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  for (;;) {
    const Eigen::Vector3d v(u(rng), u(rng), u(rng));
    switch (s.kind) {
      case ShapeKind::kBox:
        return 0.5 * v.cwiseProduct(s.size);
      case ShapeKind::kSphere:
        if (v.norm() <= 1) return s.size.x() * v;
        break;
      case ShapeKind::kCylinder:
        if (v.head<2>().norm() <= 1)
          return Eigen::Vector3d(s.size.x() * v.x(), s.size.x() * v.y(), 0.5 * s.size.y() * v.z());
        break;
      case ShapeKind::kCapsule: {
        const Eigen::Vector3d p(s.size.x() * v.x(), s.size.x() * v.y(),
                                (0.5 * s.size.y() + s.size.x()) * v.z());
        const double z = std::clamp(p.z(), -0.5 * s.size.y(), 0.5 * s.size.y());
        if ((p - Eigen::Vector3d(0, 0, z)).norm() <= s.size.x()) return p;
        break;
      }
      case ShapeKind::kMesh:
        return Eigen::Vector3d::Zero();
    }
  }
}

Eigen::Isometry3d random_pose(std::mt19937& rng, double spread) {
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
  T.translation() = spread * Eigen::Vector3d(u(rng), u(rng), u(rng));
  return T;
}

const std::vector<Shape>& shapes() {
  static const std::vector<Shape> s = {Shape::sphere(0.08),         Shape::box(0.3, 0.1, 0.05),
                                       Shape::box(0.05, 0.05, 0.6), Shape::cylinder(0.08, 0.2),
                                       Shape::cylinder(0.2, 0.05),  Shape::capsule(0.06, 0.3)};
  return s;
}

TEST(CapsuleBound, ContainsItsSolidAndIsExactForSpheresAndCapsules) {
  std::mt19937 rng(3);
  for (const Shape& s : shapes()) {
    const CapsuleBound c = capsule_bound(ConvexShape(s));
    for (int i = 0; i < 2000; ++i) {
      EXPECT_LE(point_segment(point_in(s, rng), c), c.radius + 1e-12);
    }
  }
  const CapsuleBound cap = capsule_bound(ConvexShape(Shape::capsule(0.06, 0.3)));
  EXPECT_EQ(cap.radius, 0.06);
  EXPECT_DOUBLE_EQ((cap.b - cap.a).norm(), 0.3);
  const CapsuleBound ball = capsule_bound(ConvexShape(Shape::sphere(0.08)));
  EXPECT_EQ(ball.radius, 0.08);
  EXPECT_EQ(ball.a, ball.b);
  // A cylinder's capsule is its own radius, not its bounding sphere's.
  EXPECT_EQ(capsule_bound(ConvexShape(Shape::cylinder(0.08, 0.2))).radius, 0.08);
}

TEST(CapsuleBound, EnclosingContainsEveryPart) {
  std::mt19937 rng(4);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<CapsuleBound> parts;
    for (int i = 0; i < 3; ++i) {
      const Shape& s = shapes()[rng() % shapes().size()];
      parts.push_back(transformed(random_pose(rng, 0.2), capsule_bound(ConvexShape(s))));
    }
    const CapsuleBound all = enclosing(parts);
    for (const CapsuleBound& p : parts) {
      for (int i = 0; i <= 20; ++i) {
        const Eigen::Vector3d x = p.a + (i / 20.0) * (p.b - p.a);
        EXPECT_LE(point_segment(x, all) + p.radius, all.radius + 1e-12);
      }
    }
  }
  // Three parts that make one capsule (a cylinder with a sphere at each end) enclose exactly.
  const std::vector<CapsuleBound> link = {
      CapsuleBound{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, 0.2), 0.08},
      CapsuleBound{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 0.08},
      CapsuleBound{Eigen::Vector3d(0, 0, 0.2), Eigen::Vector3d(0, 0, 0.2), 0.08}};
  EXPECT_EQ(enclosing(link).radius, 0.08);
}

TEST(CapsuleBound, SegmentDistanceIsTheMinimumOverBothSegments) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 300; ++trial) {
    Eigen::Vector3d p0(u(rng), u(rng), u(rng)), p1(u(rng), u(rng), u(rng));
    Eigen::Vector3d q0(u(rng), u(rng), u(rng)), q1(u(rng), u(rng), u(rng));
    if (trial % 4 == 1) p1 = p0;                                 // a point and a segment
    if (trial % 4 == 2) q1 = q0 + 0.5 * (p1 - p0);               // parallel segments
    if (trial % 4 == 3) q0 = 0.5 * (p0 + p1), q1 = 2 * q0 - q1;  // crossing ones
    const double d = segment_distance(p0, p1, q0, q1);
    double brute = INFINITY;
    const int n = 400;
    for (int i = 0; i <= n; ++i) {
      const Eigen::Vector3d p = p0 + (double(i) / n) * (p1 - p0);
      const CapsuleBound q{q0, q1, 0};
      brute = std::min(brute, point_segment(p, q));
    }
    EXPECT_LE(d, brute + 1e-12) << "trial " << trial;
    EXPECT_GE(d, brute - 2.0 / n) << "trial " << trial;  // the sampling's own resolution
  }
}

// Random pairs of solids close together, a third of them penetrating: every bound is at most
// the signed distance GJK/EPA reports; two capsules' bound is their exact distance.
TEST(CapsuleBound, LowerBoundsNeverExceedTheSignedDistance) {
  std::mt19937 rng(6);
  int penetrating = 0, box_bounds = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Shape& sa = shapes()[rng() % shapes().size()];
    const Shape& sb = shapes()[rng() % shapes().size()];
    const ConvexShape a(sa), b(sb);
    const Eigen::Isometry3d Ta = random_pose(rng, 0.25), Tb = random_pose(rng, 0.25);
    const PairDistance d = pair_distance(a, Ta, b, Tb);
    ASSERT_TRUE(d.valid);
    penetrating += d.distance < 0;
    const CapsuleBound ca = transformed(Ta, capsule_bound(a)),
                       cb = transformed(Tb, capsule_bound(b));
    SCOPED_TRACE("trial " + std::to_string(trial));
    EXPECT_LE(lower_bound(ca, cb), d.distance + 1e-9);
    EXPECT_LE(lower_bound(ca, Tb * b.bound_center(), b.bound_radius()), d.distance + 1e-9);
    Eigen::Vector3d lo, hi;
    b.world_aabb(Tb, lo, hi);
    const double box = lower_bound(ca, lo, hi);
    box_bounds += std::isfinite(box);
    EXPECT_LE(box, d.distance + 1e-9);
    if (sa.kind == ShapeKind::kCapsule && sb.kind == ShapeKind::kCapsule && d.distance > 0) {
      EXPECT_NEAR(lower_bound(ca, cb), d.distance, 1e-7);
    }
  }
  EXPECT_GT(penetrating, 500);
  EXPECT_GT(box_bounds, 500);
}

}  // namespace
}  // namespace kinograph::collision

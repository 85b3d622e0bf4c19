// The documented shape ranges (collision/shape.h): at their ends Bullet's signed distance to a
// 5 cm sphere matches the closed form everywhere in and around the solid, and a shape a step
// beyond them is refused with the dimension and the limit named.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "kinograph/collision/convex_shape.h"
#include "kinograph/collision/pair_distance.h"
#include "kinograph/collision/shape.h"

namespace kinograph::collision {
namespace {

constexpr double kProbeRadius = 0.05;
constexpr double kTolerance = 1e-6;  // m: far below any safety margin

// Closed-form signed distances from a point to the solids, in their own frames.
double box_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& half) {
  const Eigen::Vector3d q = p.cwiseAbs() - half;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}
double cylinder_distance(const Eigen::Vector3d& p, double radius, double half_length) {
  const Eigen::Vector2d d(std::hypot(p.x(), p.y()) - radius, std::abs(p.z()) - half_length);
  return d.cwiseMax(0.0).norm() + std::min(std::max(d.x(), d.y()), 0.0);
}
double capsule_distance(const Eigen::Vector3d& p, double radius, double half_length) {
  const double z = std::clamp(p.z(), -half_length, half_length);
  return (p - Eigen::Vector3d(0, 0, z)).norm() - radius;
}
double closed_form(const Shape& s, const Eigen::Vector3d& p) {
  switch (s.kind) {
    case ShapeKind::kBox:
      return box_distance(p, s.size / 2);
    case ShapeKind::kCylinder:
      return cylinder_distance(p, s.size.x(), s.size.y() / 2);
    case ShapeKind::kCapsule:
      return capsule_distance(p, s.size.x(), s.size.y() / 2);
    default:
      return p.norm() - s.size.x();
  }
}

// The smallest nonzero dimension of a solid (its thickness).
double thickness(const Shape& s) {
  double t = INFINITY;
  const int n = s.kind == ShapeKind::kBox ? 3 : (s.kind == ShapeKind::kSphere ? 1 : 2);
  for (int i = 0; i < n; ++i) {
    if (s.size[i] > 0) t = std::min(t, s.kind == ShapeKind::kBox ? s.size[i] : 2 * s.size[i]);
  }
  return t;
}

// Worst |Bullet − closed form| over probe centres inside, on and around the solid (near its
// centre, where EPA fails first, near faces and rims, and outside), in units of the allowed
// error: 1 µm, or the thickness of a solid thinner than the probe (a probe that swallows its
// cross-section reads a depth off by up to it); a wrong sign counts as infinite.
double worst_error(const Shape& shape) {
  const ConvexShape solid(shape);
  const ConvexShape probe(Shape::sphere(kProbeRadius));
  const double extent = shape.size.maxCoeff();
  const double t = thickness(shape);
  const double allowed = t < 2 * kProbeRadius ? std::max(kTolerance, t) : kTolerance;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Eigen::Vector3d> centres = {{0.3, 0.1, 0.2}, {1.0, 0.1, 0.0}, {0.0, 0.1, 0.0}};
  for (int k = 0; k < 300; ++k) {
    const double reach = k < 100 ? 0.05 : (k < 200 ? 0.6 : 1.2);
    centres.push_back(reach * extent * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)));
  }
  double worst = 0;
  for (const Eigen::Vector3d& p : centres) {
    Eigen::Isometry3d at = Eigen::Isometry3d::Identity();
    at.translation() = p;
    const PairDistance d = pair_distance(probe, at, solid, Eigen::Isometry3d::Identity());
    const double want = closed_form(shape, p) - kProbeRadius;
    if (!d.valid || (std::abs(want) > allowed && (d.distance < 0) != (want < 0))) return INFINITY;
    worst = std::max(worst, std::abs(d.distance - want) / allowed);
  }
  return worst;
}

TEST(ShapeRange, BulletIsFaithfulAtTheEndsOfEveryRange) {
  const double lo = kMinShapeDimension, hi = kMaxShapeDimension, cyl = kMaxCylinderDimension;
  for (const Shape& s :
       {Shape::box(hi, hi, hi), Shape::box(hi, hi, lo), Shape::box(lo, lo, lo), Shape::sphere(hi),
        Shape::sphere(lo), Shape::capsule(hi, hi), Shape::capsule(lo, hi), Shape::capsule(hi, 0),
        Shape::cylinder(cyl, cyl), Shape::cylinder(cyl, lo), Shape::cylinder(lo, cyl),
        Shape::cylinder(lo, lo)}) {
    ASSERT_EQ(range_error(s), "");
    EXPECT_LE(worst_error(s), 1.0)
        << "kind " << static_cast<int>(s.kind) << " size " << s.size.transpose();
  }
}

// The reason the ranges exist: past them Bullet mis-measures (a robot inside a huge box or
// cylinder would be called collision-free or barely touching).
TEST(ShapeRange, BulletMisMeasuresFarBeyondTheRanges) {
  EXPECT_GT(worst_error(Shape::box(1e6, 1e6, 1e6)), 1e9);   // > 1 km off
  EXPECT_GT(worst_error(Shape::cylinder(500, 1000)), 1e3);  // > 1 mm off
}

TEST(ShapeRange, ShapesBeyondTheRangesAreRefusedWithDimensionAndLimit) {
  struct Case {
    Shape shape;
    std::string names;
  };
  const std::vector<Case> cases = {
      {Shape::box(1e80, 1, 1), "box side x is 1e+80 m, beyond the 10000 m"},
      {Shape::box(1, 1, 0), "box side z is 0 m, below the 0.0001 m"},
      {Shape::box(1, NAN, 1), "box side y is nan m, not a finite number"},
      {Shape::sphere(2e4), "sphere radius is 20000 m, beyond the 10000 m"},
      {Shape::sphere(INFINITY), "sphere radius is inf m, not a finite number"},
      {Shape::cylinder(1e79, 1), "cylinder radius is 1e+79 m, beyond the 10 m"},
      {Shape::cylinder(1, 10.5), "cylinder length is 10.5 m, beyond the 10 m"},
      {Shape::capsule(0.1, -1), "capsule length is -1 m, below the 0.0001 m"},
      {Shape::mesh("x.obj", Eigen::Vector3d(1, 1e3, 1)), "mesh scale y is 1000, beyond the 100"},
  };
  for (const Case& c : cases) {
    EXPECT_NE(range_error(c.shape).find(c.names), std::string::npos)
        << "got \"" << range_error(c.shape) << "\", want \"" << c.names << "\"";
  }
  EXPECT_EQ(range_error(Shape::capsule(0.1, 0)), "");  // a capsule of length 0 is a sphere
  EXPECT_EQ(range_error(Shape::mesh("x.obj")), "");
}

TEST(ShapeRange, PositionsBeyondTheLimitAreRefused) {
  EXPECT_EQ(position_range_error(Eigen::Vector3d(1e5, -1e5, 0)), "");
  EXPECT_NE(position_range_error(Eigen::Vector3d(0, 2e5, 0)).find("position y is 200000 m"),
            std::string::npos);
  EXPECT_NE(position_range_error(Eigen::Vector3d(0, 0, NAN)).find("not a finite number"),
            std::string::npos);
}

}  // namespace
}  // namespace kinograph::collision

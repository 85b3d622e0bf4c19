#include "kinograph/collision/pair_distance.h"

#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btPointCollector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <btBulletCollisionCommon.h>

#include <cmath>

namespace kinograph::collision {
namespace {

btTransform to_bullet(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d R = T.linear();
  const Eigen::Vector3d p = T.translation();
  return btTransform(
      btMatrix3x3(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)),
      btVector3(p.x(), p.y(), p.z()));
}

Eigen::Vector3d to_eigen(const btVector3& v) { return Eigen::Vector3d(v.x(), v.y(), v.z()); }

}  // namespace

PairDistance pair_distance(const ConvexShape& a, const Eigen::Isometry3d& a_to_world,
                           const ConvexShape& b, const Eigen::Isometry3d& b_to_world,
                           double max_distance) {
  btVoronoiSimplexSolver simplex;
  btGjkEpaPenetrationDepthSolver epa;
  btGjkPairDetector detector(&a.bullet(), &b.bullet(), &simplex, &epa);
  btGjkPairDetector::ClosestPointInput input;
  input.m_transformA = to_bullet(a_to_world);
  input.m_transformB = to_bullet(b_to_world);
  // Bullet compares this bound with the distance between the core shapes (margins removed),
  // then reports only results whose final distance is below it.
  const double core_max = max_distance + a.bullet().getMargin() + b.bullet().getMargin();
  input.m_maximumDistanceSquared =
      std::isfinite(core_max) && core_max > 0 ? core_max * core_max : BT_LARGE_FLOAT;
  btPointCollector out;
  detector.getClosestPoints(input, out, nullptr);

  PairDistance result;
  if (!out.m_hasResult || out.m_distance > max_distance) return result;
  Eigen::Vector3d n = to_eigen(out.m_normalOnBInWorld);
  const double norm = n.norm();
  if (!(norm > 0)) return result;
  n /= norm;
  result.valid = true;
  result.distance = out.m_distance;
  result.normal = n;
  // Bullet reports the point on B; A's witness lies distance along the normal from it.
  result.point_on_b = to_eigen(out.m_pointInWorld);
  result.point_on_a = result.point_on_b + n * out.m_distance;
  return result;
}

}  // namespace kinograph::collision

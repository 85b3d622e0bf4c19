// Closed-form checks of the Bullet GJK/EPA signed distance: distance, sign, witness points
// and normal for every shape kind, separated, penetrating and deep.
#include "kinograph/collision/pair_distance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

#include "tests/lib/temp_dir.h"

namespace kinograph::collision {
namespace {

constexpr double kTol = 1e-6;

Eigen::Isometry3d at(double x, double y, double z) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

void expect_vec(const Eigen::Vector3d& actual, const Eigen::Vector3d& expected, double tol,
                const char* what) {
  EXPECT_LT((actual - expected).norm(), tol)
      << what << ": got " << actual.transpose() << ", expected " << expected.transpose();
}

// Checks the invariants every valid result must satisfy.
void expect_consistent(const PairDistance& r) {
  ASSERT_TRUE(r.valid);
  EXPECT_NEAR(r.normal.norm(), 1.0, 1e-9);
  // The witness points are |d| apart along the normal, A's ahead of B's when separated.
  expect_vec(r.point_on_a - r.point_on_b, r.normal * r.distance, 1e-9, "witness offset");
}

TEST(PairDistance, SphereSphereSeparatedAndPenetrating) {
  const ConvexShape a(Shape::sphere(0.3)), b(Shape::sphere(0.5));
  PairDistance r = pair_distance(a, at(0, 0, 0), b, at(2, 0, 0));
  expect_consistent(r);
  EXPECT_NEAR(r.distance, 1.2, kTol);
  expect_vec(r.point_on_a, {0.3, 0, 0}, kTol, "point on A");
  expect_vec(r.point_on_b, {1.5, 0, 0}, kTol, "point on B");
  expect_vec(r.normal, {-1, 0, 0}, kTol, "normal");

  r = pair_distance(a, at(0, 0, 0), b, at(0, 0.6, 0));
  expect_consistent(r);
  EXPECT_NEAR(r.distance, -0.2, kTol);
  expect_vec(r.normal, {0, -1, 0}, kTol, "normal");
  expect_vec(r.point_on_a, {0, 0.3, 0}, kTol, "point on A");
  expect_vec(r.point_on_b, {0, 0.1, 0}, kTol, "point on B");
}

// Sphere radius 0.5 against the box [-1,1]^3 with sharp edges: face, edge, corner and deep cases
// against their exact distances.
TEST(PairDistance, SphereBoxFaceEdgeCornerAndDeep) {
  const ConvexShape sphere(Shape::sphere(0.5)), box(Shape::box(2, 2, 2));
  struct Case {
    Eigen::Vector3d centre;
    double distance;
    Eigen::Vector3d normal;  // from box towards sphere
    Eigen::Vector3d on_box;
  };
  const double s2 = std::sqrt(0.5), s3 = std::sqrt(1.0 / 3);
  const Case cases[] = {
      {{2, 0, 0}, 0.5, {1, 0, 0}, {1, 0, 0}},
      {{1.3, 0, 0}, -0.2, {1, 0, 0}, {1, 0, 0}},
      {{0.8, 0, 0}, -0.7, {1, 0, 0}, {1, 0, 0}},
      {{0, -0.6, 0}, -0.9, {0, -1, 0}, {0, -1, 0}},
      {{2, 2, 0}, std::sqrt(2.0) - 0.5, {s2, s2, 0}, {1, 1, 0}},
      {{2, 2, 2}, std::sqrt(3.0) - 0.5, {s3, s3, s3}, {1, 1, 1}},
      {{0, 0, -5}, 3.5, {0, 0, -1}, {0, 0, -1}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(testing::Message() << "sphere at " << c.centre.transpose());
    const Eigen::Isometry3d T = at(c.centre.x(), c.centre.y(), c.centre.z());
    const PairDistance r = pair_distance(sphere, T, box, Eigen::Isometry3d::Identity());
    expect_consistent(r);
    EXPECT_NEAR(r.distance, c.distance, kTol);
    expect_vec(r.normal, c.normal, 1e-6, "normal");
    expect_vec(r.point_on_b, c.on_box, 1e-6, "point on box");
    expect_vec(r.point_on_a, c.centre - 0.5 * c.normal, 1e-6, "point on sphere");
    // Swapping the roles flips the normal and swaps the witnesses, same distance.
    const PairDistance s = pair_distance(box, Eigen::Isometry3d::Identity(), sphere, T);
    expect_consistent(s);
    EXPECT_NEAR(s.distance, c.distance, kTol);
    expect_vec(s.normal, -c.normal, 1e-6, "swapped normal");
  }
}

// Point-to-box signed distance in the box's frame: outside the Euclidean distance to the
// clamped point; inside minus the distance to the nearest face.
double point_box_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& half) {
  const Eigen::Vector3d q = p.cwiseAbs() - half;
  if ((q.array() > 0).any()) return q.cwiseMax(0.0).norm();
  return q.maxCoeff();
}

TEST(PairDistance, SphereBoxRandomPosesMatchClosedForm) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const Eigen::Vector3d half(0.4, 0.25, 0.6);
  const double radius = 0.15;
  const ConvexShape sphere(Shape::sphere(radius)), box(Shape::box(0.8, 0.5, 1.2));
  for (int i = 0; i < 200; ++i) {
    Eigen::Isometry3d box_pose = Eigen::Isometry3d::Identity();
    box_pose.linear() =
        Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
    box_pose.translation() = Eigen::Vector3d(u(rng), u(rng), u(rng));
    const Eigen::Vector3d c = box_pose.translation() + Eigen::Vector3d(u(rng), u(rng), u(rng));
    const double expected = point_box_distance(box_pose.inverse() * c, half) - radius;
    const PairDistance r = pair_distance(sphere, at(c.x(), c.y(), c.z()), box, box_pose);
    SCOPED_TRACE(i);
    expect_consistent(r);
    EXPECT_NEAR(r.distance, expected, 1e-6);
    // The box witness lies on the box surface.
    EXPECT_NEAR(point_box_distance(box_pose.inverse() * r.point_on_b, half), 0, 1e-6);
  }
}

TEST(PairDistance, BoxBoxSeparatedRotatedAndPenetrating) {
  const ConvexShape a(Shape::box(2, 2, 2)), b(Shape::box(2, 2, 2));
  PairDistance r = pair_distance(a, Eigen::Isometry3d::Identity(), b, at(2.7, 0.3, -0.2));
  expect_consistent(r);
  EXPECT_NEAR(r.distance, 0.7, kTol);
  expect_vec(r.normal, {-1, 0, 0}, kTol, "normal");
  EXPECT_NEAR(r.point_on_a.x(), 1.0, kTol);
  EXPECT_NEAR(r.point_on_b.x(), 1.7, kTol);

  // B turned 45 degrees about z: its vertical edge points at A's +x face.
  Eigen::Isometry3d tb = at(3, 0, 0);
  tb.linear() = Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  r = pair_distance(a, Eigen::Isometry3d::Identity(), b, tb);
  expect_consistent(r);
  EXPECT_NEAR(r.distance, 2 - std::sqrt(2.0), kTol);
  EXPECT_NEAR(r.point_on_b.x(), 3 - std::sqrt(2.0), kTol);
  EXPECT_NEAR(r.point_on_b.y(), 0, kTol);
  expect_vec(r.normal, {-1, 0, 0}, kTol, "normal");

  // Overlap of 0.3 along x with B much wider in y and z: the depth is along x.
  const ConvexShape wide(Shape::box(2, 6, 6));
  r = pair_distance(a, Eigen::Isometry3d::Identity(), wide, at(1.7, 0, 0));
  expect_consistent(r);
  EXPECT_NEAR(r.distance, -0.3, kTol);
  expect_vec(r.normal, {-1, 0, 0}, kTol, "normal");
  EXPECT_NEAR(r.point_on_a.x(), 1.0, kTol);
  EXPECT_NEAR(r.point_on_b.x(), 0.7, kTol);
}

TEST(PairDistance, CapsuleSphere) {
  const ConvexShape capsule(Shape::capsule(0.2, 1.0)), sphere(Shape::sphere(0.3));
  struct Case {
    Eigen::Vector3d centre;
    double distance;
    Eigen::Vector3d axis_point;  // closest point of the capsule's segment
  };
  const Case cases[] = {
      {{1, 0, 0.3}, 0.5, {0, 0, 0.3}},      // beside the cylindrical part
      {{0, 0, 1.5}, 0.5, {0, 0, 0.5}},      // above the top cap
      {{0.6, 0, -1.3}, 0.5, {0, 0, -0.5}},  // diagonal off the bottom cap
      {{0, 0.4, 0}, -0.1, {0, 0, 0}},       // penetrating the side
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(testing::Message() << "sphere at " << c.centre.transpose());
    const PairDistance r = pair_distance(capsule, Eigen::Isometry3d::Identity(), sphere,
                                         at(c.centre.x(), c.centre.y(), c.centre.z()));
    expect_consistent(r);
    EXPECT_NEAR(r.distance, c.distance, kTol);
    const Eigen::Vector3d dir = (c.axis_point - c.centre).normalized();  // towards capsule
    expect_vec(r.normal, dir, 1e-6, "normal");
    expect_vec(r.point_on_a, c.axis_point - 0.2 * dir, 1e-6, "point on capsule");
    expect_vec(r.point_on_b, c.centre + 0.3 * dir, 1e-6, "point on sphere");
  }
}

TEST(PairDistance, CylinderSphereSideTopRimPenetrating) {
  const ConvexShape cylinder(Shape::cylinder(0.2, 1.0)), sphere(Shape::sphere(0.3));
  struct Case {
    Eigen::Vector3d centre;
    double distance;
    Eigen::Vector3d on_cylinder;
  };
  const Case cases[] = {
      {{1, 0, 0.2}, 0.5, {0.2, 0, 0.2}},    // side
      {{0, 0, 1.5}, 0.7, {0, 0, 0.5}},      // top face
      {{0.5, 0, 0.9}, 0.2, {0.2, 0, 0.5}},  // rim: sharp, since the margin is 0
      {{0, -0.4, 0}, -0.1, {0, -0.2, 0}},   // penetrating the side
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(testing::Message() << "sphere at " << c.centre.transpose());
    const PairDistance r = pair_distance(cylinder, Eigen::Isometry3d::Identity(), sphere,
                                         at(c.centre.x(), c.centre.y(), c.centre.z()));
    expect_consistent(r);
    EXPECT_NEAR(r.distance, c.distance, kTol);
    expect_vec(r.point_on_a, c.on_cylinder, 1e-6, "point on cylinder");
  }
}

// Writes a cube of side 2 as an OBJ file (with an interior vertex the hull must ignore).
std::string write_cube_obj() {
  static const kinograph::test_support::TempDir dir("kinograph_collision_cube");
  const auto path = dir / "cube.obj";
  std::ofstream f(path);
  for (int i = 0; i < 8; ++i) {
    f << "v " << ((i & 1) ? 1 : -1) << ' ' << ((i & 2) ? 1 : -1) << ' ' << ((i & 4) ? 1 : -1)
      << '\n';
  }
  f << "v 0.1 0.2 0.3\n";
  const int faces[12][3] = {{1, 3, 4}, {1, 4, 2}, {5, 6, 8}, {5, 8, 7}, {1, 2, 6}, {1, 6, 5},
                            {3, 7, 8}, {3, 8, 4}, {1, 5, 7}, {1, 7, 3}, {2, 4, 8}, {2, 8, 6}};
  for (const auto& t : faces) f << "f " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  f << "f 9 1 2\n";
  return path.string();
}

TEST(PairDistance, MeshConvexHullOfCubeMatchesBox) {
  const std::string path = write_cube_obj();
  // Scale 0.5 in x: the hull is the box [-0.5,0.5] x [-1,1] x [-1,1].
  const ConvexShape hull(Shape::mesh(path, Eigen::Vector3d(0.5, 1, 1)));
  const ConvexShape sphere(Shape::sphere(0.5));
  EXPECT_GE(hull.bound_radius(), std::sqrt(2.25) - 1e-12);
  struct Case {
    Eigen::Vector3d centre;
    double distance;
  };
  const Case cases[] = {{{1.5, 0, 0}, 0.5},
                        {{0.8, 0, 0}, -0.2},
                        {{0.3, 0, 0}, -0.7},
                        {{1.5, 2, 0}, std::sqrt(2.0) - 0.5}};
  for (const Case& c : cases) {
    SCOPED_TRACE(testing::Message() << "sphere at " << c.centre.transpose());
    const PairDistance r = pair_distance(sphere, at(c.centre.x(), c.centre.y(), c.centre.z()), hull,
                                         Eigen::Isometry3d::Identity());
    expect_consistent(r);
    EXPECT_NEAR(r.distance, c.distance, kTol);
  }
  std::filesystem::remove(path);
}

// GJK's early exit at max_distance must only drop pairs that are farther than it, and must
// not change the distance of the others (including penetrating ones).
TEST(PairDistance, MaxDistanceOnlyDropsFartherPairs) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  const ConvexShape shapes[] = {
      ConvexShape(Shape::sphere(0.1)), ConvexShape(Shape::box(0.3, 0.2, 0.5)),
      ConvexShape(Shape::cylinder(0.1, 0.4)), ConvexShape(Shape::capsule(0.05, 0.3))};
  int kept = 0, dropped = 0;
  for (int i = 0; i < 400; ++i) {
    const ConvexShape& a = shapes[i % 4];
    const ConvexShape& b = shapes[(i / 4) % 4];
    Eigen::Isometry3d ta = Eigen::Isometry3d::Identity(), tb = Eigen::Isometry3d::Identity();
    ta.linear() =
        Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
    tb.linear() =
        Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
    tb.translation() = 0.6 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    const double max_distance = 0.3 * u(rng);
    const PairDistance full = pair_distance(a, ta, b, tb);
    const PairDistance capped = pair_distance(a, ta, b, tb, max_distance);
    ASSERT_TRUE(full.valid);
    SCOPED_TRACE(testing::Message()
                 << "case " << i << " d " << full.distance << " max " << max_distance);
    EXPECT_EQ(capped.valid, full.distance <= max_distance);
    if (capped.valid) {
      EXPECT_EQ(capped.distance, full.distance);
      ++kept;
    } else {
      ++dropped;
    }
  }
  EXPECT_GT(kept, 50);
  EXPECT_GT(dropped, 50);
}

TEST(PairDistance, BadShapesThrowNamingTheProblem) {
  EXPECT_THROW(ConvexShape(Shape::sphere(0)), std::invalid_argument);
  EXPECT_THROW(ConvexShape(Shape::box(1, -1, 1)), std::invalid_argument);
  try {
    ConvexShape s(Shape::mesh("/nonexistent/thing.stl"));
    FAIL() << "expected an exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/thing.stl"), std::string::npos);
  }
}

}  // namespace
}  // namespace kinograph::collision

// A mesh's convex hull is read and computed once per file and scale, shared by every shape made
// from it, and read again when the file changes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "kinograph/collision/convex_shape.h"
#include "kinograph/collision/pair_distance.h"
#include "tests/lib/temp_dir.h"

namespace kinograph::collision {
namespace {

// Writes a cube of side 2·half as an OBJ file.
void write_cube(const std::filesystem::path& path, double half) {
  std::ofstream f(path);
  for (int i = 0; i < 8; ++i) {
    f << "v " << ((i & 1) ? half : -half) << ' ' << ((i & 2) ? half : -half) << ' '
      << ((i & 4) ? half : -half) << '\n';
  }
  const int faces[12][3] = {{1, 3, 4}, {1, 4, 2}, {5, 6, 8}, {5, 8, 7}, {1, 2, 6}, {1, 6, 5},
                            {3, 7, 8}, {3, 8, 4}, {1, 5, 7}, {1, 7, 3}, {2, 4, 8}, {2, 8, 6}};
  for (const auto& t : faces) f << "f " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
}

// Signed distance from a unit sphere at (x, 0, 0) to the shape at the origin.
double sphere_distance(const ConvexShape& shape, double x) {
  const ConvexShape sphere(Shape::sphere(1.0));
  Eigen::Isometry3d at = Eigen::Isometry3d::Identity();
  at.translation().x() = x;
  return pair_distance(sphere, at, shape, Eigen::Isometry3d::Identity()).distance;
}

TEST(MeshHullCache, EachFileAndScaleIsReadOnce) {
  const test_support::TempDir dir("kinograph_mesh_hull_cache");
  const std::string path = (dir / "cube.obj").string();
  write_cube(path, 1.0);
  const int before = mesh_hulls_computed();
  const ConvexShape a(Shape::mesh(path));
  const ConvexShape b(Shape::mesh("file://" + path));  // the same file
  EXPECT_EQ(mesh_hulls_computed(), before + 1);
  EXPECT_EQ(&a.bullet(), &b.bullet());  // one hull, shared
  EXPECT_EQ(a.bound_radius(), b.bound_radius());
  EXPECT_NEAR(sphere_distance(b, 3.0), 1.0, 1e-9);
  const ConvexShape half(Shape::mesh(path, Eigen::Vector3d(0.5, 0.5, 0.5)));  // its own hull
  EXPECT_EQ(mesh_hulls_computed(), before + 2);
  EXPECT_NEAR(sphere_distance(half, 3.0), 1.5, 1e-9);
}

TEST(MeshHullCache, ARewrittenFileIsReadAgain) {
  const test_support::TempDir dir("kinograph_mesh_hull_cache");
  const std::string path = (dir / "cube.obj").string();
  write_cube(path, 1.0);
  const ConvexShape small(Shape::mesh(path));
  const int before = mesh_hulls_computed();
  write_cube(path, 1.25);  // another size on disk
  const ConvexShape large(Shape::mesh(path));
  EXPECT_EQ(mesh_hulls_computed(), before + 1);
  EXPECT_NEAR(sphere_distance(large, 3.0), 0.75, 1e-9);
  EXPECT_NEAR(sphere_distance(small, 3.0), 1.0, 1e-9);  // a shape keeps the hull it was made with
}

TEST(MeshHullCache, AnUnreadableMeshFailsEveryTimeNamingTheFile) {
  const test_support::TempDir dir("kinograph_mesh_hull_cache");
  const std::string path = (dir / "broken.obj").string();
  std::ofstream(path) << "v 0 0 0\nv 1 0 0\nf 1 2 1\n";  // too few vertices for a hull
  for (int attempt = 0; attempt < 2; ++attempt) {
    try {
      const ConvexShape s(Shape::mesh(path));
      ADD_FAILURE() << "no error";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("broken.obj"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(ConvexShape(Shape::mesh((dir / "missing.obj").string())), std::invalid_argument);
}

}  // namespace
}  // namespace kinograph::collision

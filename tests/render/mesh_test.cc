// Tessellated primitives against closed forms (volume, extents, unit normals) and mesh files
// through assimp (OBJ with materials, STL, missing file).
#include "render/mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "tests/lib/temp_dir.h"

namespace kinograph::render {
namespace {

// Volume enclosed by a closed, outward-wound triangle mesh (divergence theorem): it is only
// right if the surface is closed and every triangle faces out.
double enclosed_volume(const Mesh& mesh) {
  double volume = 0.0;
  for (std::size_t i = 0; i < mesh.indices.size(); i += 3) {
    Eigen::Vector3d p[3];
    for (int k = 0; k < 3; ++k) {
      const auto& v = mesh.vertices[mesh.indices[i + k]].position;
      p[k] = Eigen::Vector3d(v[0], v[1], v[2]);
    }
    volume += p[0].dot(p[1].cross(p[2])) / 6.0;
  }
  return volume;
}

void expect_unit_normals(const Mesh& mesh) {
  for (const Vertex& v : mesh.vertices) {
    EXPECT_NEAR(Eigen::Vector3f(v.normal[0], v.normal[1], v.normal[2]).norm(), 1.0f, 1e-5f);
  }
}

TEST(Primitives, BoxHasExactVolumeAndExtents) {
  const Mesh box = make_box(Eigen::Vector3d(0.2, 0.4, 1.0));
  EXPECT_NEAR(enclosed_volume(box), 0.08, 1e-6);
  EXPECT_TRUE(box.bounds().min().isApprox(Eigen::Vector3d(-0.1, -0.2, -0.5), 1e-6));
  EXPECT_TRUE(box.bounds().max().isApprox(Eigen::Vector3d(0.1, 0.2, 0.5), 1e-6));
  expect_unit_normals(box);
}

TEST(Primitives, SphereCylinderCapsuleVolumesConverge) {
  const double r = 0.3, l = 0.8, pi = std::numbers::pi;
  // Inscribed polyhedra: a little under the true volume, within 2% at the default density and
  // closer when finer (positive volume also proves the triangles face outward).
  const double sphere = 4.0 / 3.0 * pi * r * r * r;
  EXPECT_NEAR(enclosed_volume(make_sphere(r)), sphere, 0.02 * sphere);
  EXPECT_LT(enclosed_volume(make_sphere(r)), sphere);
  EXPECT_NEAR(enclosed_volume(make_sphere(r, 128, 64)), sphere, 0.005 * sphere);
  const double cylinder = pi * r * r * l;
  EXPECT_NEAR(enclosed_volume(make_cylinder(r, l)), cylinder, 0.02 * cylinder);
  const double capsule = cylinder + sphere;
  EXPECT_NEAR(enclosed_volume(make_capsule(r, l)), capsule, 0.02 * capsule);
  EXPECT_NEAR(make_capsule(r, l).bounds().max().z(), l / 2 + r, 1e-6);
  EXPECT_NEAR(make_cylinder(r, l).bounds().max().z(), l / 2, 1e-6);
  expect_unit_normals(make_sphere(r));
  expect_unit_normals(make_capsule(r, l));
}

TEST(Primitives, SphereNormalsPointOutward) {
  const Mesh sphere = make_sphere(2.0, 16, 8);
  for (const Vertex& v : sphere.vertices) {
    const Eigen::Vector3f p(v.position[0], v.position[1], v.position[2]);
    const Eigen::Vector3f n(v.normal[0], v.normal[1], v.normal[2]);
    EXPECT_NEAR(p.norm(), 2.0f, 1e-5f);
    EXPECT_GT(n.dot(p), 1.99f);
  }
}

TEST(Primitives, TubeFollowsThePolyline) {
  const std::vector<Eigen::Vector3d> path = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}};
  const Mesh tube = make_tube(path, 0.05);
  const Eigen::AlignedBox3d box = tube.bounds();
  EXPECT_NEAR(box.min().x(), -0.05, 1e-6);
  EXPECT_NEAR(box.max().y(), 1.05, 1e-6);
  EXPECT_NEAR(box.max().z(), 0.05, 1e-6);
}

class MeshFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test_support::TempDir::make(
        std::string("kinograph_mesh_test") + "_" +
        ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(MeshFiles, ObjWithMaterialGivesColouredTriangles) {
  std::ofstream(dir_ / "cube.mtl") << "newmtl green\nKd 0.1 0.8 0.2\n";
  std::ofstream obj(dir_ / "cube.obj");
  obj << "mtllib cube.mtl\nusemtl green\n";
  for (int i = 0; i < 8; ++i) {
    obj << "v " << (i & 1 ? 1 : -1) << " " << (i & 2 ? 1 : -1) << " " << (i & 4 ? 1 : -1) << "\n";
  }
  // Quads (assimp triangulates): faces of the [-1,1]^3 cube, outward.
  obj << "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  obj.close();
  const Mesh mesh = load_mesh((dir_ / "cube.obj").string(), Eigen::Vector3d(0.5, 1.0, 2.0));
  EXPECT_EQ(mesh.indices.size(), 36u);
  EXPECT_TRUE(mesh.has_colors);
  EXPECT_NEAR(mesh.vertices.front().color[1], 0.8f, 1e-6f);
  EXPECT_TRUE(mesh.bounds().max().isApprox(Eigen::Vector3d(0.5, 1.0, 2.0), 1e-6));
  EXPECT_NEAR(std::abs(enclosed_volume(mesh)), 8.0, 1e-5);
}

TEST_F(MeshFiles, StlHasNoMaterialColours) {
  std::ofstream stl(dir_ / "tet.stl");
  stl << "solid t\n";
  const double v[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const int f[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (const auto& tri : f) {
    stl << "facet normal 0 0 0\nouter loop\n";
    for (int k : tri) stl << "vertex " << v[k][0] << " " << v[k][1] << " " << v[k][2] << "\n";
    stl << "endloop\nendfacet\n";
  }
  stl << "endsolid t\n";
  stl.close();
  const Mesh mesh = load_mesh((dir_ / "tet.stl").string());
  EXPECT_EQ(mesh.indices.size(), 12u);
  EXPECT_FALSE(mesh.has_colors);  // the URDF's colour applies
  EXPECT_NEAR(enclosed_volume(mesh), 1.0 / 6.0, 1e-6);
}

TEST_F(MeshFiles, MissingFileNamesIt) {
  const std::string path = (dir_ / "missing.stl").string();
  try {
    load_mesh(path);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  MeshCache cache;
  EXPECT_THROW(cache.get(path), std::runtime_error);
  EXPECT_EQ(cache.size(), 0u);
}

TEST(MeshCache, LoadsEachFileOnce) {
  const std::string wam = "/usr/share/doc/dart/data/urdf/wam/meshes/wam/wam1.dae";
  if (!std::filesystem::exists(wam)) GTEST_SKIP() << "dart-doc is not installed";
  MeshCache cache;
  const auto a = cache.get(wam);
  const auto b = cache.get(wam);
  EXPECT_EQ(a.get(), b.get());
  EXPECT_GT(a->indices.size(), 300u);
  const auto scaled = cache.get(wam, Eigen::Vector3d::Constant(2.0));
  EXPECT_NE(scaled.get(), a.get());
  EXPECT_TRUE(scaled->bounds().sizes().isApprox(2.0 * a->bounds().sizes(), 1e-6));
}

}  // namespace
}  // namespace kinograph::render

#pragma once
// Triangle meshes on the CPU side: tessellated URDF primitives and meshes loaded through assimp.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace kinograph::render {

/// One vertex as the GPU takes it: position and normal in the mesh frame, RGBA colour.
struct Vertex {
  std::array<float, 3> position;
  std::array<float, 3> normal;
  std::array<float, 4> color;
};

/// An indexed triangle list. `has_colors` is true when the colours come from the file's
/// materials; otherwise they are white and the geometry's own colour is used.
struct Mesh {
  std::vector<Vertex> vertices;
  std::vector<std::uint32_t> indices;  ///< three per triangle, counter-clockwise outside
  bool has_colors = false;

  /// Axis-aligned bounds of the vertices in the mesh frame (empty box if no vertices).
  Eigen::AlignedBox3d bounds() const;
  /// Appends `other` with its vertices moved by `pose` (normals rotated).
  void append(const Mesh& other, const Eigen::Isometry3d& pose = Eigen::Isometry3d::Identity());
};

/// Sphere of radius r centred at the origin.
Mesh make_sphere(double radius, int slices = 32, int stacks = 16);
/// Box with full extents `size`, centred at the origin (flat-shaded faces).
Mesh make_box(const Eigen::Vector3d& size);
/// Closed cylinder of radius r and length `length` along z, centred at the origin.
Mesh make_cylinder(double radius, double length, int slices = 32);
/// Capsule: cylinder of length `length` along z with hemispherical caps of radius r.
Mesh make_capsule(double radius, double length, int slices = 32, int stacks = 8);
/// Tube of radius r along a polyline (the end-effector path); joints are smooth enough at
/// the sample density of a trajectory.
Mesh make_tube(const std::vector<Eigen::Vector3d>& points, double radius, int slices = 12);
/// Checkerboard floor in the z = 0 plane, centred at the origin, `cells` × `cells` squares
/// of side `cell`, in two colours (normals +z).
Mesh make_checker(int cells, double cell, const Eigen::Vector4f& light,
                  const Eigen::Vector4f& dark);

/// Loads STL, DAE, OBJ (any format assimp reads) as one mesh in the file's root frame, scaled
/// per axis; material diffuse colours become vertex colours. Throws std::runtime_error naming
/// the file if it is missing or unreadable.
Mesh load_mesh(const std::string& path, const Eigen::Vector3d& scale = Eigen::Vector3d::Ones());

/// Loads each mesh file once (keyed by path and scale); later requests share the same mesh.
class MeshCache {
 public:
  /// The mesh of `path` at `scale`, loaded on first use; throws as load_mesh does.
  std::shared_ptr<const Mesh> get(const std::string& path,
                                  const Eigen::Vector3d& scale = Eigen::Vector3d::Ones());
  /// Number of distinct meshes held.
  std::size_t size() const { return meshes_.size(); }

 private:
  std::map<std::string, std::shared_ptr<const Mesh>> meshes_;
};

}  // namespace kinograph::render

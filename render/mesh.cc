#include "render/mesh.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include <assimp/Importer.hpp>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace kinograph::render {

namespace {

constexpr std::array<float, 4> kWhite = {1.f, 1.f, 1.f, 1.f};

Vertex make_vertex(const Eigen::Vector3d& p, const Eigen::Vector3d& n,
                   const std::array<float, 4>& c = kWhite) {
  return Vertex{
      {float(p.x()), float(p.y()), float(p.z())}, {float(n.x()), float(n.y()), float(n.z())}, c};
}

// A surface of revolution about z: `profile` gives (radius, z, normal_r, normal_z) per ring,
// from bottom to top; rings of zero radius become poles.
Mesh revolve(const std::vector<std::array<double, 4>>& profile, int slices) {
  Mesh mesh;
  for (const auto& [r, z, nr, nz] : profile) {
    for (int s = 0; s <= slices; ++s) {
      const double phi = 2.0 * std::numbers::pi * s / slices;
      const double c = std::cos(phi), si = std::sin(phi);
      mesh.vertices.push_back(
          make_vertex({r * c, r * si, z}, Eigen::Vector3d(nr * c, nr * si, nz).normalized()));
    }
  }
  const auto ring = static_cast<std::uint32_t>(slices + 1);
  for (std::uint32_t i = 0; i + 1 < profile.size(); ++i) {
    for (std::uint32_t s = 0; s < static_cast<std::uint32_t>(slices); ++s) {
      const std::uint32_t a = i * ring + s, b = a + 1, c = a + ring, d = c + 1;
      mesh.indices.insert(mesh.indices.end(), {a, b, d, a, d, c});
    }
  }
  return mesh;
}

Mesh disk(double radius, double z, double normal_z, int slices) {
  Mesh mesh;
  const Eigen::Vector3d n(0, 0, normal_z);
  mesh.vertices.push_back(make_vertex({0, 0, z}, n));
  for (int s = 0; s <= slices; ++s) {
    const double phi = 2.0 * std::numbers::pi * s / slices;
    mesh.vertices.push_back(make_vertex({radius * std::cos(phi), radius * std::sin(phi), z}, n));
  }
  for (std::uint32_t s = 1; s <= static_cast<std::uint32_t>(slices); ++s) {
    if (normal_z > 0) {
      mesh.indices.insert(mesh.indices.end(), {0, s, s + 1});
    } else {
      mesh.indices.insert(mesh.indices.end(), {0, s + 1, s});
    }
  }
  return mesh;
}

}  // namespace

Eigen::AlignedBox3d Mesh::bounds() const {
  Eigen::AlignedBox3d box;
  for (const Vertex& v : vertices) {
    box.extend(Eigen::Vector3d(v.position[0], v.position[1], v.position[2]));
  }
  return box;
}

void Mesh::append(const Mesh& other, const Eigen::Isometry3d& pose) {
  const auto offset = static_cast<std::uint32_t>(vertices.size());
  for (Vertex v : other.vertices) {
    const Eigen::Vector3d p = pose * Eigen::Vector3d(v.position[0], v.position[1], v.position[2]);
    const Eigen::Vector3d n =
        pose.linear() * Eigen::Vector3d(v.normal[0], v.normal[1], v.normal[2]);
    vertices.push_back(make_vertex(p, n, v.color));
  }
  for (std::uint32_t i : other.indices) indices.push_back(i + offset);
  has_colors = has_colors || other.has_colors;
}

Mesh make_sphere(double radius, int slices, int stacks) {
  std::vector<std::array<double, 4>> profile;
  for (int i = 0; i <= stacks; ++i) {
    const double theta = std::numbers::pi * (double(i) / stacks - 0.5);  // -pi/2 .. pi/2
    profile.push_back(
        {radius * std::cos(theta), radius * std::sin(theta), std::cos(theta), std::sin(theta)});
  }
  return revolve(profile, slices);
}

Mesh make_box(const Eigen::Vector3d& size) {
  Mesh mesh;
  const Eigen::Vector3d h = 0.5 * size;
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {-1, 1}) {
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      n[axis] = sign;
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
      for (auto [su, sv] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
        Eigen::Vector3d p;
        p[axis] = sign * h[axis];
        p[u] = su * h[u];
        p[v] = sv * h[v];
        mesh.vertices.push_back(make_vertex(p, n));
      }
      // (u, v, axis) is right-handed, so u→v is counter-clockwise seen from +axis.
      if (sign > 0) {
        mesh.indices.insert(mesh.indices.end(),
                            {base, base + 1, base + 2, base, base + 2, base + 3});
      } else {
        mesh.indices.insert(mesh.indices.end(),
                            {base, base + 2, base + 1, base, base + 3, base + 2});
      }
    }
  }
  return mesh;
}

Mesh make_cylinder(double radius, double length, int slices) {
  const double h = 0.5 * length;
  Mesh mesh = revolve({{radius, -h, 1, 0}, {radius, h, 1, 0}}, slices);
  mesh.append(disk(radius, h, 1, slices));
  mesh.append(disk(radius, -h, -1, slices));
  return mesh;
}

Mesh make_capsule(double radius, double length, int slices, int stacks) {
  const double h = 0.5 * length;
  std::vector<std::array<double, 4>> profile;
  for (int i = 0; i <= stacks; ++i) {  // bottom cap: theta -pi/2 .. 0
    const double theta = 0.5 * std::numbers::pi * (double(i) / stacks - 1.0);
    profile.push_back({radius * std::cos(theta), -h + radius * std::sin(theta), std::cos(theta),
                       std::sin(theta)});
  }
  for (int i = 0; i <= stacks; ++i) {  // top cap: theta 0 .. pi/2
    const double theta = 0.5 * std::numbers::pi * double(i) / stacks;
    profile.push_back(
        {radius * std::cos(theta), h + radius * std::sin(theta), std::cos(theta), std::sin(theta)});
  }
  return revolve(profile, slices);
}

Mesh make_tube(const std::vector<Eigen::Vector3d>& points, double radius, int slices) {
  Mesh mesh;
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    const Eigen::Vector3d d = points[i + 1] - points[i];
    const double len = d.norm();
    if (len < 1e-9) continue;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), d / len).toRotationMatrix();
    pose.translation() = 0.5 * (points[i] + points[i + 1]);
    mesh.append(revolve({{radius, -0.5 * len, 1, 0}, {radius, 0.5 * len, 1, 0}}, slices), pose);
  }
  // Small spheres at the joints hide the gaps between segments.
  const Mesh joint = make_sphere(radius, slices, slices / 2);
  for (const Eigen::Vector3d& p : points) {
    mesh.append(joint, Eigen::Isometry3d(Eigen::Translation3d(p)));
  }
  return mesh;
}

Mesh make_checker(int cells, double cell, const Eigen::Vector4f& light,
                  const Eigen::Vector4f& dark) {
  Mesh mesh;
  mesh.has_colors = true;
  const double origin = -0.5 * cells * cell;
  const Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  for (int i = 0; i < cells; ++i) {
    for (int j = 0; j < cells; ++j) {
      const Eigen::Vector4f& c4 = ((i + j) % 2 == 0) ? light : dark;
      const std::array<float, 4> c = {c4[0], c4[1], c4[2], c4[3]};
      const double x0 = origin + i * cell, y0 = origin + j * cell;
      const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
      mesh.vertices.push_back(make_vertex({x0, y0, 0}, n, c));
      mesh.vertices.push_back(make_vertex({x0 + cell, y0, 0}, n, c));
      mesh.vertices.push_back(make_vertex({x0 + cell, y0 + cell, 0}, n, c));
      mesh.vertices.push_back(make_vertex({x0, y0 + cell, 0}, n, c));
      mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
  }
  return mesh;
}

namespace {

void collect_node(const aiScene* scene, const aiNode* node, const aiMatrix4x4& parent,
                  const std::vector<std::array<float, 4>>& material_colors,
                  const Eigen::Vector3d& scale, Mesh& out) {
  const aiMatrix4x4 transform = parent * node->mTransformation;
  aiMatrix3x3 normal_matrix(transform);
  normal_matrix.Inverse().Transpose();
  for (unsigned m = 0; m < node->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[node->mMeshes[m]];
    const auto base = static_cast<std::uint32_t>(out.vertices.size());
    const std::array<float, 4> color = material_colors.at(mesh->mMaterialIndex);
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D p = transform * mesh->mVertices[v];
      aiVector3D n = mesh->HasNormals() ? normal_matrix * mesh->mNormals[v] : aiVector3D(0, 0, 1);
      // A non-uniform scale bends normals by the inverse scale.
      Eigen::Vector3d ne(n.x / scale.x(), n.y / scale.y(), n.z / scale.z());
      if (ne.norm() > 0) ne.normalize();
      out.vertices.push_back(make_vertex(
          Eigen::Vector3d(p.x * scale.x(), p.y * scale.y(), p.z * scale.z()), ne, color));
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines left by Triangulate
      out.indices.insert(out.indices.end(), {base + face.mIndices[0], base + face.mIndices[1],
                                             base + face.mIndices[2]});
    }
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c) {
    collect_node(scene, node->mChildren[c], transform, material_colors, scale, out);
  }
}

}  // namespace

Mesh load_mesh(const std::string& path, const Eigen::Vector3d& scale) {
  Assimp::Importer importer;
  // Points and lines carry no surface; dropping them keeps every primitive a triangle.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene =
      importer.ReadFile(path, aiProcess_Triangulate | aiProcess_GenSmoothNormals |
                                  aiProcess_JoinIdenticalVertices | aiProcess_SortByPType);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw std::runtime_error(
        fmt::format("cannot load mesh '{}': {}", path, importer.GetErrorString()));
  }
  // Materials give colours only when the file names real ones: assimp invents a grey
  // "DefaultMaterial" for formats without materials (STL), which must not override the URDF's.
  std::vector<std::array<float, 4>> colors;
  bool has_colors = false;
  for (unsigned i = 0; i < scene->mNumMaterials; ++i) {
    const aiMaterial* material = scene->mMaterials[i];
    aiString name;
    material->Get(AI_MATKEY_NAME, name);
    aiColor4D diffuse(1, 1, 1, 1);
    const bool has_diffuse = material->Get(AI_MATKEY_COLOR_DIFFUSE, diffuse) == AI_SUCCESS;
    const bool is_default = std::string(name.C_Str()) == AI_DEFAULT_MATERIAL_NAME;
    if (has_diffuse && !is_default) {
      has_colors = true;
      float opacity = 1.f;
      material->Get(AI_MATKEY_OPACITY, opacity);
      colors.push_back({diffuse.r, diffuse.g, diffuse.b, diffuse.a * opacity});
    } else {
      colors.push_back(kWhite);
    }
  }
  if (colors.empty()) colors.push_back(kWhite);
  Mesh mesh;
  collect_node(scene, scene->mRootNode, aiMatrix4x4(), colors, scale, mesh);
  if (mesh.indices.empty()) {
    throw std::runtime_error(fmt::format("mesh '{}' has no triangles", path));
  }
  mesh.has_colors = has_colors;
  return mesh;
}

std::shared_ptr<const Mesh> MeshCache::get(const std::string& path, const Eigen::Vector3d& scale) {
  const std::string key = fmt::format("{}|{}|{}|{}", path, scale.x(), scale.y(), scale.z());
  auto it = meshes_.find(key);
  if (it != meshes_.end()) return it->second;
  auto mesh = std::make_shared<const Mesh>(load_mesh(path, scale));
  meshes_.emplace(key, mesh);
  return mesh;
}

}  // namespace kinograph::render

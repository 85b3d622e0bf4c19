#include "kinograph/collision/convex_shape.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <btBulletCollisionCommon.h>

#include <assimp/Importer.hpp>
#include <atomic>
#include <filesystem>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#ifndef BT_USE_DOUBLE_PRECISION
#error "kinograph_collision must be compiled against bullet-float64 (BT_USE_DOUBLE_PRECISION)"
#endif

namespace kinograph::collision {
namespace {

void require_positive(double v, const char* what) {
  if (!(v > 0)) {
    throw std::invalid_argument(std::string("collision shape: ") + what +
                                " must be positive, got " + std::to_string(v));
  }
}

// Collects every vertex of every mesh in the scene, in the file's root frame.
void collect_vertices(const aiScene* scene, const aiNode* node, const aiMatrix4x4& parent,
                      const Eigen::Vector3d& scale, std::vector<Eigen::Vector3d>& out) {
  const aiMatrix4x4 tf = parent * node->mTransformation;
  for (unsigned i = 0; i < node->mNumMeshes; ++i) {
    const aiMesh* mesh = scene->mMeshes[node->mMeshes[i]];
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D p = tf * mesh->mVertices[v];
      out.emplace_back(scale.x() * p.x, scale.y() * p.y, scale.z() * p.z);
    }
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c) {
    collect_vertices(scene, node->mChildren[c], tf, scale, out);
  }
}

// The file a mesh Shape names.
std::string mesh_file(const Shape& s) {
  return s.mesh_path.rfind("file://", 0) == 0 ? s.mesh_path.substr(7) : s.mesh_path;
}

std::vector<Eigen::Vector3d> load_mesh_vertices(const Shape& s) {
  const std::string path = mesh_file(s);
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path, aiProcess_JoinIdenticalVertices);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw std::invalid_argument("collision mesh '" + s.mesh_path +
                                "' cannot be read: " + importer.GetErrorString());
  }
  std::vector<Eigen::Vector3d> vertices;
  collect_vertices(scene, scene->mRootNode, aiMatrix4x4(), s.mesh_scale, vertices);
  if (vertices.size() < 4) {
    throw std::invalid_argument("collision mesh '" + s.mesh_path + "' has " +
                                std::to_string(vertices.size()) +
                                " vertices; a convex hull needs at least 4");
  }
  return vertices;
}

// A mesh's hull as the shapes made from it share it.
struct MeshHull {
  std::shared_ptr<const btConvexShape> shape;
  Eigen::Vector3d bound_center = Eigen::Vector3d::Zero();
  double bound_radius = 0;
};

// A mesh file as read: path, scale, size and modification time (a rewritten file is read again).
using MeshKey = std::tuple<std::string, double, double, double, std::uintmax_t, std::int64_t>;

// Hulls stay cached for the process's life; past this many (scenes of ever new meshes) the
// cache starts over, the shapes made meanwhile keeping theirs.
constexpr size_t kMaxCachedHulls = 256;

std::mutex g_hulls_mutex;
std::map<MeshKey, MeshHull> g_hulls;
std::atomic<int> g_hulls_computed{0};

MeshHull compute_hull(const Shape& shape) {
  const std::vector<Eigen::Vector3d> vertices = load_mesh_vertices(shape);
  auto hull = std::make_unique<btConvexHullShape>();
  Eigen::Vector3d lo = vertices.front(), hi = vertices.front();
  for (const Eigen::Vector3d& v : vertices) {
    hull->addPoint(btVector3(v.x(), v.y(), v.z()), false);
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  hull->recalcLocalAabb();
  hull->optimizeConvexHull();  // keep only hull vertices: support queries scan them all
  // btConvexHullShape adds its margin outside the hull; 0 keeps the hull exact.
  hull->setMargin(0);
  MeshHull out;
  out.bound_center = (lo + hi) / 2;
  for (const Eigen::Vector3d& v : vertices) {
    out.bound_radius = std::max(out.bound_radius, (v - out.bound_center).norm());
  }
  out.shape = std::move(hull);
  ++g_hulls_computed;
  return out;
}

// The hull of a mesh Shape, from the cache when its file has not changed since it was read.
MeshHull mesh_hull(const Shape& shape) {
  const std::string path = mesh_file(shape);
  std::error_code size_error, time_error;
  const std::uintmax_t size = std::filesystem::file_size(path, size_error);
  const auto time = std::filesystem::last_write_time(path, time_error);
  if (size_error || time_error) return compute_hull(shape);  // the reader says what is wrong
  const MeshKey key{path,
                    shape.mesh_scale.x(),
                    shape.mesh_scale.y(),
                    shape.mesh_scale.z(),
                    size,
                    static_cast<std::int64_t>(time.time_since_epoch().count())};
  {
    const std::lock_guard<std::mutex> lock(g_hulls_mutex);
    const auto it = g_hulls.find(key);
    if (it != g_hulls.end()) return it->second;
  }
  MeshHull hull = compute_hull(shape);  // unlocked: other meshes' hulls meanwhile
  const std::lock_guard<std::mutex> lock(g_hulls_mutex);
  if (g_hulls.size() >= kMaxCachedHulls) g_hulls.clear();
  return g_hulls.emplace(key, std::move(hull)).first->second;  // the first one made, if two
}

}  // namespace

int mesh_hulls_computed() { return g_hulls_computed.load(); }

ConvexShape::ConvexShape(const Shape& shape) : shape_(shape) {
  const Eigen::Vector3d& sz = shape.size;
  switch (shape.kind) {
    case ShapeKind::kSphere: {
      require_positive(sz.x(), "sphere radius");
      bullet_ = std::make_unique<btSphereShape>(sz.x());  // radius is the margin
      bound_radius_ = sz.x();
      break;
    }
    case ShapeKind::kBox: {
      require_positive(sz.x(), "box x extent");
      require_positive(sz.y(), "box y extent");
      require_positive(sz.z(), "box z extent");
      auto box = std::make_unique<btBoxShape>(btVector3(sz.x() / 2, sz.y() / 2, sz.z() / 2));
      box->setMargin(0);  // keeps the outer size and makes edges and corners sharp
      bullet_ = std::move(box);
      bound_radius_ = sz.norm() / 2;
      break;
    }
    case ShapeKind::kCylinder: {
      require_positive(sz.x(), "cylinder radius");
      require_positive(sz.y(), "cylinder length");
      auto cyl = std::make_unique<btCylinderShapeZ>(btVector3(sz.x(), sz.x(), sz.y() / 2));
      cyl->setMargin(0);  // sharp rims, exact outer size
      bullet_ = std::move(cyl);
      bound_radius_ = std::hypot(sz.x(), sz.y() / 2);
      break;
    }
    case ShapeKind::kCapsule: {
      require_positive(sz.x(), "capsule radius");
      if (!(sz.y() >= 0)) throw std::invalid_argument("collision shape: capsule length < 0");
      // btCapsuleShapeZ's height is the distance between the cap centres, as ours.
      bullet_ = std::make_unique<btCapsuleShapeZ>(sz.x(), sz.y());
      bound_radius_ = sz.x() + sz.y() / 2;
      break;
    }
    case ShapeKind::kMesh: {
      MeshHull hull = mesh_hull(shape);
      bullet_ = std::move(hull.shape);
      bound_center_ = hull.bound_center;
      bound_radius_ = hull.bound_radius;
      break;
    }
  }
}

void ConvexShape::world_aabb(const Eigen::Isometry3d& pose, Eigen::Vector3d& lo,
                             Eigen::Vector3d& hi) const {
  const Eigen::Matrix3d R = pose.linear();
  const Eigen::Vector3d p = pose.translation();
  const btTransform T(
      btMatrix3x3(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)),
      btVector3(p.x(), p.y(), p.z()));
  btVector3 bmin, bmax;
  bullet_->getAabb(T, bmin, bmax);
  lo = Eigen::Vector3d(bmin.x(), bmin.y(), bmin.z());
  hi = Eigen::Vector3d(bmax.x(), bmax.y(), bmax.z());
}

ConvexShape::~ConvexShape() = default;
ConvexShape::ConvexShape(ConvexShape&&) noexcept = default;
ConvexShape& ConvexShape::operator=(ConvexShape&&) noexcept = default;

void bullet_precision_link_guard() {
  btSphereShape s(1);
  btVector3 inertia;
  // Qualified, non-virtual call into the library: undefined reference on a precision mismatch.
  s.btSphereShape::calculateLocalInertia(btScalar(1), inertia);
}

}  // namespace kinograph::collision

#pragma once
// Draws lit triangle meshes, opaque or as translucent ghosts, into an off-screen picture made
// of one or more panels (viewports), each with its own camera.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "render/camera.h"
#include "render/gl_context.h"
#include "render/image.h"
#include "render/mesh.h"

namespace kinograph::render {

/// Options of the GL renderer.
struct RendererOptions {
  int samples = 4;  ///< MSAA samples per pixel
  /// Lighting (view space, so the light follows the camera): a key light from the upper
  /// left, a weaker fill from the right, ambient and a little specular.
  float ambient = 0.28f;
  float key = 0.72f;
  float fill = 0.28f;
  float specular = 0.18f;
};

/// Handle of a mesh uploaded to the GPU.
using MeshId = int;

/// One mesh instance to draw: which mesh, where (world pose times a per-axis scale) and in
/// what colour (`use_mesh_colors` keeps the mesh's own material colours when it has them).
struct DrawItem {
  MeshId mesh = -1;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  Eigen::Vector4f color = Eigen::Vector4f(0.7f, 0.7f, 0.7f, 1.f);
  bool use_mesh_colors = true;
};

/// Immediate-mode renderer over a GlContext. Usage: begin(), then for each panel
/// set_panel() and draw()/draw_ghost(), then finish() for the picture. Not thread-safe.
class Renderer {
 public:
  explicit Renderer(const RendererOptions& options = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// The id of the mesh stored under `key`, building and uploading it with `make` on first
  /// use (so URDF primitives and mesh files are tessellated/loaded once per renderer).
  MeshId mesh(const std::string& key, const std::function<Mesh()>& make);
  /// Uploads `mesh` under `key`, replacing what was there (for per-picture meshes such as the
  /// end-effector path, which must not pile up).
  MeshId upload(const std::string& key, const Mesh& mesh);
  /// Bounds of an uploaded mesh in its own frame.
  const Eigen::AlignedBox3d& mesh_bounds(MeshId id) const;

  /// Starts a picture of width × height filled with `background`.
  void begin(int width, int height, const Eigen::Vector4f& background);
  /// Directs drawing to the panel at (x, y) (top-left origin) of size w × h, seen by `camera`.
  void set_panel(int x, int y, int w, int h, const Camera& camera);
  /// Draws opaque items with depth testing.
  void draw(const std::vector<DrawItem>& items);
  /// Draws items as one translucent object of opacity `alpha`: a depth pre-pass keeps the
  /// object's own hidden surfaces from showing through, so a ghost reads as a solid shape.
  void draw_ghost(const std::vector<DrawItem>& items, float alpha);
  /// Resolves the antialiased picture and returns it (top row first).
  Image finish();

  /// GL_RENDERER string, for reports.
  const char* renderer_name() const { return context_.renderer_name(); }

 private:
  struct GpuMesh;
  void draw_items(const std::vector<DrawItem>& items, float alpha);

  RendererOptions options_;
  GlContext context_;
  std::vector<GpuMesh> meshes_;
  std::vector<std::pair<std::string, MeshId>> keys_;  // few entries; linear search is fine
  unsigned program_ = 0;
  int u_model_view_ = -1, u_projection_ = -1, u_normal_matrix_ = -1, u_color_ = -1,
      u_use_vertex_color_ = -1, u_alpha_ = -1, u_light_ = -1;
  Eigen::Matrix4f view_ = Eigen::Matrix4f::Identity();
  int height_ = 0;
};

}  // namespace kinograph::render

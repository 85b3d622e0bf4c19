#pragma once
// A headless OpenGL 3.3 core-profile context (OSMesa, llvmpipe) that renders into an
// antialiased off-screen framebuffer and reads it back as an Image.
#include <memory>

#include "render/image.h"

namespace kinograph::render {

/// Options of the off-screen context.
struct GlContextOptions {
  int samples = 4;  ///< MSAA samples per pixel (clamped to what the driver offers; 0 = off)
};

/// RAII owner of an OSMesa core-profile context and its multisampled framebuffer. The context
/// is made current on construction; one per thread. Throws std::runtime_error if OSMesa fails.
class GlContext {
 public:
  explicit GlContext(const GlContextOptions& options = {});
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  /// Makes this context current on the calling thread (needed only when several exist).
  void make_current();
  /// Binds a width × height multisampled target (reallocated only when the size changes).
  void bind_target(int width, int height);
  /// Resolves the multisampled target and reads it back, flipping OpenGL's Y-up rows.
  Image read_target();

  /// The MSAA sample count actually in use.
  int samples() const;
  /// GL_RENDERER of the driver, for logs and benchmark reports.
  const char* renderer_name() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace kinograph::render

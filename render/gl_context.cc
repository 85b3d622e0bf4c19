#include "render/gl_context.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/gl.h"

namespace kinograph::render {

struct GlContext::Impl {
  OSMesaContext context = nullptr;
  // OSMesa needs a client buffer to make the context current; all drawing goes to the FBOs.
  std::vector<unsigned char> dummy = std::vector<unsigned char>(4 * 4 * 4);
  int samples = 0;
  int width = 0, height = 0;
  GLuint msaa_fbo = 0, msaa_color = 0, msaa_depth = 0;
  GLuint resolve_fbo = 0, resolve_color = 0;
  std::vector<unsigned char> readback;

  void make_current() {
    if (!OSMesaMakeCurrent(context, dummy.data(), GL_UNSIGNED_BYTE, 4, 4)) {
      throw std::runtime_error("GlContext: OSMesaMakeCurrent failed");
    }
  }

  void free_targets() {
    if (msaa_fbo) glDeleteFramebuffers(1, &msaa_fbo);
    if (resolve_fbo) glDeleteFramebuffers(1, &resolve_fbo);
    GLuint rbs[] = {msaa_color, msaa_depth, resolve_color};
    glDeleteRenderbuffers(3, rbs);
    msaa_fbo = msaa_color = msaa_depth = resolve_fbo = resolve_color = 0;
  }
};

GlContext::GlContext(const GlContextOptions& options) : impl_(std::make_unique<Impl>()) {
  load_gl();
  const int attribs[] = {OSMESA_FORMAT,
                         OSMESA_RGBA,
                         OSMESA_DEPTH_BITS,
                         24,
                         OSMESA_PROFILE,
                         OSMESA_CORE_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION,
                         3,
                         OSMESA_CONTEXT_MINOR_VERSION,
                         3,
                         0};
  impl_->context = OSMesaCreateContextAttribs(attribs, nullptr);
  if (impl_->context == nullptr) {
    throw std::runtime_error("GlContext: OSMesaCreateContextAttribs (core 3.3) failed");
  }
  impl_->make_current();
  GLint max_samples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  impl_->samples = std::clamp(options.samples, 0, static_cast<int>(max_samples));
  spdlog::debug("GlContext: {} ({}), {} MSAA samples",
                reinterpret_cast<const char*>(glGetString(GL_RENDERER)),
                reinterpret_cast<const char*>(glGetString(GL_VERSION)), impl_->samples);
}

GlContext::~GlContext() {
  if (impl_->context != nullptr) {
    impl_->make_current();
    impl_->free_targets();
    OSMesaDestroyContext(impl_->context);
  }
}

void GlContext::make_current() { impl_->make_current(); }

int GlContext::samples() const { return impl_->samples; }

const char* GlContext::renderer_name() const {
  return reinterpret_cast<const char*>(glGetString(GL_RENDERER));
}

void GlContext::bind_target(int width, int height) {
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument("GlContext: target size must be positive, got " +
                                std::to_string(width) + "x" + std::to_string(height));
  }
  Impl& m = *impl_;
  if (width != m.width || height != m.height) {
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_size);
    if (width > max_size || height > max_size) {
      throw std::invalid_argument("GlContext: target " + std::to_string(width) + "x" +
                                  std::to_string(height) + " exceeds the driver's maximum " +
                                  std::to_string(max_size));
    }
    m.free_targets();
    glGenFramebuffers(1, &m.msaa_fbo);
    glGenRenderbuffers(1, &m.msaa_color);
    glGenRenderbuffers(1, &m.msaa_depth);
    glBindRenderbuffer(GL_RENDERBUFFER, m.msaa_color);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, m.samples, GL_RGBA8, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, m.msaa_depth);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, m.samples, GL_DEPTH24_STENCIL8, width,
                                     height);
    glBindFramebuffer(GL_FRAMEBUFFER, m.msaa_fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, m.msaa_color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER,
                              m.msaa_depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      throw std::runtime_error("GlContext: multisampled framebuffer incomplete");
    }
    glGenFramebuffers(1, &m.resolve_fbo);
    glGenRenderbuffers(1, &m.resolve_color);
    glBindRenderbuffer(GL_RENDERBUFFER, m.resolve_color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, m.resolve_fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                              m.resolve_color);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      throw std::runtime_error("GlContext: resolve framebuffer incomplete");
    }
    m.width = width;
    m.height = height;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, m.msaa_fbo);
  glViewport(0, 0, width, height);
}

Image GlContext::read_target() {
  Impl& m = *impl_;
  glBindFramebuffer(GL_READ_FRAMEBUFFER, m.msaa_fbo);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, m.resolve_fbo);
  glBlitFramebuffer(0, 0, m.width, m.height, 0, 0, m.width, m.height, GL_COLOR_BUFFER_BIT,
                    GL_NEAREST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, m.resolve_fbo);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  m.readback.resize(static_cast<std::size_t>(m.width) * m.height * 4);
  glReadPixels(0, 0, m.width, m.height, GL_RGBA, GL_UNSIGNED_BYTE, m.readback.data());
  Image image;
  image.width = m.width;
  image.height = m.height;
  image.rgba.resize(m.readback.size());
  const std::size_t stride = static_cast<std::size_t>(m.width) * 4;
  for (int y = 0; y < m.height; ++y) {  // OpenGL rows are bottom-up
    std::copy_n(m.readback.data() + (m.height - 1 - y) * stride, stride, image.at(0, y));
  }
  glBindFramebuffer(GL_FRAMEBUFFER, m.msaa_fbo);
  return image;
}

}  // namespace kinograph::render

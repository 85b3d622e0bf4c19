#pragma once
// OpenGL and OSMesa entry points, loaded from libOSMesa when the first GL context is made
// (load_gl), not linked: libOSMesa pulls in libLLVM, whose loading and static initializers
// would otherwise cost every kinograph verb, not only the ones that draw. libOSMesa exports
// every gl* symbol itself; never load libGL as well (docs/build.md).
//
// Each entry point is a pointer of the function's own type with the function's own name in
// namespace kinograph::render, so code in that namespace calls glClear(...) as usual: ordinary
// lookup finds the pointer before the global prototype, which is never referenced.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
// clang-format off
#include <GL/osmesa.h>
// clang-format on

// Every entry point the renderer uses; a new call needs its name here.
#define KINOGRAPH_GL_ENTRY_POINTS(X)                                                           \
  X(OSMesaCreateContextAttribs) X(OSMesaMakeCurrent) X(OSMesaDestroyContext)                   \
  X(glAttachShader) X(glBindBuffer) X(glBindFramebuffer) X(glBindRenderbuffer)                 \
  X(glBindVertexArray) X(glBlendFuncSeparate) X(glBlitFramebuffer) X(glBufferData)             \
  X(glCheckFramebufferStatus) X(glClear) X(glClearColor) X(glClearDepth) X(glColorMask)        \
  X(glCompileShader) X(glCreateProgram) X(glCreateShader) X(glDeleteBuffers)                   \
  X(glDeleteFramebuffers) X(glDeleteProgram) X(glDeleteRenderbuffers) X(glDeleteShader)        \
  X(glDeleteVertexArrays) X(glDepthFunc) X(glDepthMask) X(glDisable) X(glDrawElements)         \
  X(glEnable) X(glEnableVertexAttribArray) X(glFinish) X(glFramebufferRenderbuffer)            \
  X(glGenBuffers) X(glGenFramebuffers) X(glGenRenderbuffers) X(glGenVertexArrays)              \
  X(glGetIntegerv) X(glGetProgramiv) X(glGetShaderInfoLog) X(glGetShaderiv) X(glGetString)     \
  X(glGetUniformLocation) X(glLinkProgram) X(glPixelStorei) X(glReadPixels)                     \
  X(glRenderbufferStorage) X(glRenderbufferStorageMultisample) X(glShaderSource)                \
  X(glUniform1f) X(glUniform1i) X(glUniform4f) X(glUniform4fv) X(glUniformMatrix3fv)           \
  X(glUniformMatrix4fv) X(glUseProgram) X(glVertexAttribPointer) X(glViewport)

namespace kinograph::render {

#define KINOGRAPH_GL_DECLARE(name) extern decltype(&::name) name;
KINOGRAPH_GL_ENTRY_POINTS(KINOGRAPH_GL_DECLARE)
#undef KINOGRAPH_GL_DECLARE

/// Loads libOSMesa and every entry point above, once per process (thread-safe).
/// @throws std::runtime_error naming the library or the symbol when it cannot be loaded.
void load_gl();

}  // namespace kinograph::render

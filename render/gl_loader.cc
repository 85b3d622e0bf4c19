#include <dlfcn.h>

#include <mutex>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "render/gl.h"

namespace kinograph::render {

#define KINOGRAPH_GL_DEFINE(name) decltype(&::name) name = nullptr;
KINOGRAPH_GL_ENTRY_POINTS(KINOGRAPH_GL_DEFINE)
#undef KINOGRAPH_GL_DEFINE

namespace {

void load_gl_once() {
  // RTLD_LOCAL: the GL symbols stay out of the global namespace, so nothing else binds to them.
  void* lib = dlopen(KINOGRAPH_OSMESA_SONAME, RTLD_NOW | RTLD_LOCAL);
  if (lib == nullptr) {
    const char* why = dlerror();
    throw std::runtime_error(std::string("cannot load the off-screen renderer ") +
                             KINOGRAPH_OSMESA_SONAME + " (Debian package libosmesa6): " +
                             (why ? why : "unknown error"));
  }
  const auto load = [lib](auto& pointer, const char* name) {
    void* symbol = dlsym(lib, name);
    if (symbol == nullptr) {
      throw std::runtime_error(std::string(KINOGRAPH_OSMESA_SONAME) + " has no " + name);
    }
    pointer = reinterpret_cast<std::remove_reference_t<decltype(pointer)>>(symbol);
  };
#define KINOGRAPH_GL_LOAD(name) load(name, #name);
  KINOGRAPH_GL_ENTRY_POINTS(KINOGRAPH_GL_LOAD)
#undef KINOGRAPH_GL_LOAD
}

}  // namespace

void load_gl() {
  static std::once_flag once;
  std::call_once(once, load_gl_once);
}

}  // namespace kinograph::render

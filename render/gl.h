#pragma once
// OpenGL entry points come straight from libOSMesa (it exports every gl* symbol), so no loader
// is needed; never link libGL as well (docs/build.md).
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

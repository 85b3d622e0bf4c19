#pragma once
// Conversion between Image (RGBA bytes) and cairo's native-endian premultiplied ARGB32
// surfaces; internal to render/ (plots and labels).
#include <cairo.h>

#include "render/image.h"

namespace kinograph::render::detail {

/// A new cairo surface holding a copy of `image` (alpha premultiplied).
cairo_surface_t* to_cairo(const Image& image);
/// Copies a cairo ARGB32 surface back into an Image (alpha un-premultiplied).
Image from_cairo(cairo_surface_t* surface);

}  // namespace kinograph::render::detail

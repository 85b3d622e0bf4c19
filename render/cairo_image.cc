#include "render/cairo_image.h"

#include <cstdint>
#include <cstring>

namespace kinograph::render::detail {

cairo_surface_t* to_cairo(const Image& image) {
  cairo_surface_t* surface =
      cairo_image_surface_create(CAIRO_FORMAT_ARGB32, image.width, image.height);
  cairo_surface_flush(surface);
  unsigned char* data = cairo_image_surface_get_data(surface);
  const int stride = cairo_image_surface_get_stride(surface);
  for (int y = 0; y < image.height; ++y) {
    auto* row = reinterpret_cast<std::uint32_t*>(data + y * stride);
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.at(x, y);
      const std::uint32_t a = p[3];
      const std::uint32_t r = p[0] * a / 255, g = p[1] * a / 255, b = p[2] * a / 255;
      row[x] = (a << 24) | (r << 16) | (g << 8) | b;
    }
  }
  cairo_surface_mark_dirty(surface);
  return surface;
}

Image from_cairo(cairo_surface_t* surface) {
  cairo_surface_flush(surface);
  Image image(cairo_image_surface_get_width(surface), cairo_image_surface_get_height(surface));
  const unsigned char* data = cairo_image_surface_get_data(surface);
  const int stride = cairo_image_surface_get_stride(surface);
  for (int y = 0; y < image.height; ++y) {
    const auto* row = reinterpret_cast<const std::uint32_t*>(data + y * stride);
    for (int x = 0; x < image.width; ++x) {
      const std::uint32_t v = row[x];
      const std::uint32_t a = v >> 24;
      std::uint8_t* p = image.at(x, y);
      p[3] = static_cast<std::uint8_t>(a);
      if (a == 0) {
        p[0] = p[1] = p[2] = 0;
        continue;
      }
      p[0] = static_cast<std::uint8_t>(((v >> 16) & 0xff) * 255 / a);
      p[1] = static_cast<std::uint8_t>(((v >> 8) & 0xff) * 255 / a);
      p[2] = static_cast<std::uint8_t>((v & 0xff) * 255 / a);
    }
  }
  return image;
}

}  // namespace kinograph::render::detail

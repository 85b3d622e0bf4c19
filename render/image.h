#pragma once
// An RGBA8 picture in memory, top row first, as the renderer and the plots produce it.
#include <cstdint>
#include <string>
#include <vector>

namespace kinograph::render {

/// 8-bit RGBA pixels, row-major, row 0 at the top (PNG order, not OpenGL's Y-up order).
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;  ///< width * height * 4 bytes

  Image() = default;
  /// A width × height picture filled with one colour.
  Image(int w, int h, std::uint8_t r = 0, std::uint8_t g = 0, std::uint8_t b = 0,
        std::uint8_t a = 255);

  /// Pointer to the 4 bytes of pixel (x, y), y counted from the top.
  std::uint8_t* at(int x, int y) {
    return rgba.data() + (static_cast<std::size_t>(y) * width + x) * 4;
  }
  const std::uint8_t* at(int x, int y) const {
    return rgba.data() + (static_cast<std::size_t>(y) * width + x) * 4;
  }
  /// Copies `src` with its top-left corner at (x, y), clipped to this picture.
  void paste(const Image& src, int x, int y);
};

/// Options of the PNG encoder; the defaults favour speed (frame strips are written often).
struct PngOptions {
  int compression_level = 3;  ///< zlib level 0–9; 3 is ~2× faster than 6 for a few % more bytes
  bool keep_alpha = false;    ///< false writes RGB (smaller); the renderer's pictures are opaque
};

/// Writes `image` as a PNG file; throws std::runtime_error naming the file when it cannot.
void write_png(const Image& image, const std::string& path, const PngOptions& options = {});

/// Reads a PNG file into RGBA8 (any bit depth/colour type is converted); throws naming the file.
Image read_png(const std::string& path);

}  // namespace kinograph::render

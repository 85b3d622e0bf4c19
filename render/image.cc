#include "render/image.h"

#include <png.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <stdexcept>

namespace kinograph::render {

Image::Image(int w, int h, std::uint8_t r, std::uint8_t g, std::uint8_t b, std::uint8_t a)
    : width(w), height(h), rgba(static_cast<std::size_t>(w) * h * 4) {
  for (std::size_t i = 0; i < rgba.size(); i += 4) {
    rgba[i] = r;
    rgba[i + 1] = g;
    rgba[i + 2] = b;
    rgba[i + 3] = a;
  }
}

void Image::paste(const Image& src, int x, int y) {
  const int x0 = std::max(0, x), x1 = std::min(width, x + src.width);
  if (x1 <= x0) return;
  for (int row = std::max(0, y); row < std::min(height, y + src.height); ++row) {
    std::copy_n(src.at(x0 - x, row - y), (x1 - x0) * 4, at(x0, row));
  }
}

namespace {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

// libpng reports errors by longjmp; the message is kept here so the C++ side can throw it.
struct PngErrorSink {
  char message[256] = "unknown libpng error";
};

void png_error_handler(png_structp png, png_const_charp message) {
  auto* sink = static_cast<PngErrorSink*>(png_get_error_ptr(png));
  std::snprintf(sink->message, sizeof(sink->message), "%s", message);
  png_longjmp(png, 1);
}

void png_warning_ignored(png_structp, png_const_charp) {}

// All libpng calls live in these two functions, and no C++ object is created after setjmp, so
// the longjmp skips no destructor.
bool encode_png(std::FILE* file, const Image& image, const PngOptions& options,
                std::vector<std::uint8_t>& row, PngErrorSink& sink) {
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, &sink, png_error_handler, png_warning_ignored);
  if (png == nullptr) return false;
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, file);
  png_set_compression_level(png, options.compression_level);
  png_set_filter(png, 0, PNG_FILTER_SUB);  // cheap filter that suits rendered scenes well
  png_set_IHDR(png, info, image.width, image.height, 8,
               options.keep_alpha ? PNG_COLOR_TYPE_RGBA : PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y) {
    const std::uint8_t* src = image.at(0, y);
    if (options.keep_alpha) {
      std::copy_n(src, static_cast<std::size_t>(image.width) * 4, row.data());
    } else {
      for (int x = 0; x < image.width; ++x) std::copy_n(src + 4 * x, 3, row.data() + 3 * x);
    }
    png_write_row(png, row.data());
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

bool decode_png(std::FILE* file, Image& image, std::vector<png_bytep>& rows, PngErrorSink& sink) {
  png_structp png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, &sink, png_error_handler, png_warning_ignored);
  if (png == nullptr) return false;
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_init_io(png, file);
  png_read_info(png, info);
  png_set_expand(png);
  png_set_strip_16(png);
  png_set_gray_to_rgb(png);
  png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER);
  png_read_update_info(png, info);
  image.width = static_cast<int>(png_get_image_width(png, info));
  image.height = static_cast<int>(png_get_image_height(png, info));
  image.rgba.resize(static_cast<std::size_t>(image.width) * image.height * 4);
  rows.resize(image.height);
  for (int y = 0; y < image.height; ++y) rows[y] = image.at(0, y);
  png_read_image(png, rows.data());
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

}  // namespace

void write_png(const Image& image, const std::string& path, const PngOptions& options) {
  if (image.width <= 0 || image.height <= 0) {
    throw std::runtime_error("write_png: empty image for '" + path + "'");
  }
  File file(std::fopen(path.c_str(), "wb"));
  if (!file) throw std::runtime_error("write_png: cannot open '" + path + "' for writing");
  std::vector<std::uint8_t> row(static_cast<std::size_t>(image.width) * 4);
  PngErrorSink sink;
  if (!encode_png(file.get(), image, options, row, sink)) {
    throw std::runtime_error("write_png: '" + path + "': " + sink.message);
  }
  if (std::fflush(file.get()) != 0) {
    throw std::runtime_error("write_png: error while writing '" + path + "'");
  }
}

Image read_png(const std::string& path) {
  File file(std::fopen(path.c_str(), "rb"));
  if (!file) throw std::runtime_error("read_png: cannot open '" + path + "'");
  Image image;
  std::vector<png_bytep> rows;
  PngErrorSink sink;
  if (!decode_png(file.get(), image, rows, sink)) {
    throw std::runtime_error("read_png: '" + path + "': " + sink.message);
  }
  return image;
}

}  // namespace kinograph::render

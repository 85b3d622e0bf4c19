// PNG writing/reading round trip and the picture helpers.
#include "render/image.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "tests/lib/temp_dir.h"

namespace kinograph::render {
namespace {

std::string temp_path(const std::string& name) {
  static const kinograph::test_support::TempDir dir("kinograph_image_test");
  return (dir / name).string();
}

TEST(Image, PngRoundTripKeepsEveryPixel) {
  std::mt19937 rng(7);
  Image image(37, 23);
  for (std::uint8_t& b : image.rgba) b = static_cast<std::uint8_t>(rng());
  const std::string path = temp_path("rgba.png");
  write_png(image, path, PngOptions{.compression_level = 6, .keep_alpha = true});
  const Image back = read_png(path);
  EXPECT_EQ(back.width, 37);
  EXPECT_EQ(back.height, 23);
  EXPECT_EQ(back.rgba, image.rgba);
  std::filesystem::remove(path);
}

TEST(Image, RgbPngDropsAlphaAndKeepsColour) {
  Image image(5, 4, 10, 200, 30);
  *image.at(4, 3) = 250;  // bottom-right pixel's red: checks row order (top row first)
  const std::string path = temp_path("rgb.png");
  write_png(image, path);
  const Image back = read_png(path);
  ASSERT_EQ(back.width, 5);
  EXPECT_EQ(back.at(0, 0)[1], 200);
  EXPECT_EQ(back.at(4, 3)[0], 250);
  EXPECT_EQ(back.at(4, 3)[3], 255);
  EXPECT_EQ(back.at(0, 3)[0], 10);
  std::filesystem::remove(path);
}

TEST(Image, PasteClipsAtTheEdges) {
  Image dst(4, 4, 0, 0, 0);
  const Image src(3, 3, 255, 0, 0);
  dst.paste(src, 2, -1);
  EXPECT_EQ(dst.at(2, 0)[0], 255);
  EXPECT_EQ(dst.at(3, 1)[0], 255);
  EXPECT_EQ(dst.at(3, 2)[0], 0);
  EXPECT_EQ(dst.at(1, 0)[0], 0);
}

TEST(Image, BadPathsAreClearErrors) {
  try {
    read_png("/nonexistent/kinograph/x.png");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/kinograph/x.png"), std::string::npos);
  }
  EXPECT_THROW(write_png(Image(2, 2), "/nonexistent/kinograph/x.png"), std::runtime_error);
  EXPECT_THROW(write_png(Image(), temp_path("empty.png")), std::runtime_error);
  // A file that is not a PNG: libpng's error comes back as an exception, not an abort.
  const std::string junk = temp_path("junk.png");
  {
    std::FILE* f = std::fopen(junk.c_str(), "wb");
    std::fputs("not a png at all", f);
    std::fclose(f);
  }
  EXPECT_THROW(read_png(junk), std::runtime_error);
  std::filesystem::remove(junk);
}

}  // namespace
}  // namespace kinograph::render

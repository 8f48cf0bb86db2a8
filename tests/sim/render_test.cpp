// The frame renderer: the fitted mesh covers the image centre, the background stays white, depth
// order is respected, and the PNG reads back as written.
#include "clothcd/sim/render.hpp"

#include <gtest/gtest.h>
#include <png.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "clothcd/core/error.hpp"

namespace clothcd::sim {
namespace {

std::array<int, 3> pixel(const Image& img, int x, int y) {
  const std::size_t i = 3 * (static_cast<std::size_t>(y) * img.width + x);
  return {img.rgb[i], img.rgb[i + 1], img.rgb[i + 2]};
}

TEST(Render, FitsMeshAndKeepsNearestSurface) {
  // A red square at z = 0 and a smaller blue square in front of it (z = 1, nearer the "front"
  // camera on +z).
  const std::vector<Vec3> back = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  const std::vector<Vec3> front = {{-0.2, -0.2, 1}, {0.2, -0.2, 1}, {0.2, 0.2, 1}, {-0.2, 0.2, 1}};
  const std::vector<Face> faces = {{0, 1, 2}, {0, 2, 3}};
  const Image img =
      render({{&front, &faces, {0, 0, 1}}, {&back, &faces, {1, 0, 0}}}, {100, 100, "front"});
  ASSERT_EQ(img.rgb.size(), 100u * 100u * 3u);
  const auto centre = pixel(img, 50, 50);
  EXPECT_EQ(centre[0], 0);
  EXPECT_GT(centre[2], 0);
  const auto side = pixel(img, 20, 50);
  EXPECT_GT(side[0], 0);
  EXPECT_EQ(side[2], 0);
  const auto corner = pixel(img, 0, 0);  // outside the 92% fit
  EXPECT_EQ(corner, (std::array<int, 3>{255, 255, 255}));
  EXPECT_THROW((void)render({}, {10, 10, "sideways"}), InputError);
}

// libpng reads back exactly the pixels written, in their rows and order; an image whose size
// does not match its bytes is refused before anything is written.
TEST(Render, PngRoundTrip) {
  Image img;
  img.width = 300;
  img.height = 200;
  img.rgb.resize(300 * 200 * 3);
  for (std::size_t i = 0; i < img.rgb.size(); ++i)
    img.rgb[i] = static_cast<unsigned char>((i * 7919u) ^ (i >> 9));
  const auto path = std::filesystem::temp_directory_path() / "clothcd_render_test.png";
  write_png(path, img);
  png_image back{};
  back.version = PNG_IMAGE_VERSION;
  ASSERT_NE(png_image_begin_read_from_file(&back, path.c_str()), 0) << back.message;
  EXPECT_EQ(back.width, 300u);
  EXPECT_EQ(back.height, 200u);
  back.format = PNG_FORMAT_RGB;
  std::vector<unsigned char> pixels(PNG_IMAGE_SIZE(back));
  ASSERT_NE(png_image_finish_read(&back, nullptr, pixels.data(), 0, nullptr), 0) << back.message;
  std::filesystem::remove(path);
  EXPECT_EQ(pixels, img.rgb);

  Image bad = img;
  bad.rgb.pop_back();
  EXPECT_THROW(write_png(path, bad), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace clothcd::sim

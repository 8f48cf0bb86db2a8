// The frame renderer: the fitted mesh covers the image centre, the background stays white, depth
// order is respected, and the PNG has the expected layout.
#include "clothcd/sim/render.hpp"

#include <gtest/gtest.h>

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

TEST(Render, PngLayout) {
  Image img;
  img.width = 300;  // 900 bytes per row: the data spans several stored blocks
  img.height = 200;
  img.rgb.assign(300 * 200 * 3, 7);
  const auto path = std::filesystem::temp_directory_path() / "clothcd_render_test.png";
  write_png(path, img);
  std::ifstream in(path, std::ios::binary);
  const std::vector<unsigned char> b((std::istreambuf_iterator<char>(in)),
                                     std::istreambuf_iterator<char>());
  std::filesystem::remove(path);
  const std::size_t raw = (300 * 3 + 1) * 200;
  const std::size_t blocks = (raw + 65534) / 65535;
  // signature + IHDR (25) + IDAT (12 + 2 + 5 per block + raw + 4) + IEND (12)
  EXPECT_EQ(b.size(), 8 + 25 + 12 + 2 + 5 * blocks + raw + 4 + 12);
  ASSERT_GE(b.size(), 24u);
  EXPECT_EQ(b[1], 'P');
  EXPECT_EQ(b[12], 'I');
  EXPECT_EQ(b[15], 'R');
  EXPECT_EQ((b[16] << 24) | (b[17] << 16) | (b[18] << 8) | b[19], 300);
  EXPECT_EQ((b[20] << 24) | (b[21] << 16) | (b[22] << 8) | b[23], 200);
}

}  // namespace
}  // namespace clothcd::sim

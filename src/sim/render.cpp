// Orthographic z-buffer rasterizer; PNG files through libpng.
#include "clothcd/sim/render.hpp"

#include <fmt/format.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "clothcd/core/atomic_file.hpp"
#include "clothcd/core/error.hpp"

namespace clothcd::sim {
namespace {

struct Camera {
  Vec3 right, up, forward;  // forward points from the camera into the scene
};

Camera camera_for(const std::string& view) {
  Vec3 f;
  Vec3 up = Vec3::UnitY();
  if (view == "front") {
    f = Vec3(0, 0, -1);
  } else if (view == "back") {
    f = Vec3(0, 0, 1);
  } else if (view == "side") {
    f = Vec3(-1, 0, 0);
  } else if (view == "top") {
    f = Vec3(0, -1, 0);
    up = Vec3(0, 0, -1);
  } else if (view == "iso") {
    f = Vec3(-1, -0.7, -1).normalized();
  } else {
    throw InputError(fmt::format("unknown view '{}' (front, back, side, top, iso)", view));
  }
  Camera c;
  c.forward = f;
  c.right = f.cross(up).normalized();
  c.up = c.right.cross(f).normalized();
  return c;
}

}  // namespace

Image render(const std::vector<RenderMesh>& meshes, const RenderOptions& opt) {
  if (opt.width <= 0 || opt.height <= 0 || opt.width > 16384 || opt.height > 16384) {
    throw InputError(fmt::format("image size {}x{} is out of range", opt.width, opt.height));
  }
  const Camera cam = camera_for(opt.view);
  Image img;
  img.width = opt.width;
  img.height = opt.height;
  img.rgb.assign(static_cast<std::size_t>(opt.width) * opt.height * 3, 255);
  // Fit the projected bounding box.
  double lo_x = INFINITY, hi_x = -INFINITY, lo_y = INFINITY, hi_y = -INFINITY;
  for (const RenderMesh& m : meshes) {
    for (const Vec3& p : *m.positions) {
      if (!p.allFinite()) continue;
      lo_x = std::min(lo_x, p.dot(cam.right));
      hi_x = std::max(hi_x, p.dot(cam.right));
      lo_y = std::min(lo_y, p.dot(cam.up));
      hi_y = std::max(hi_y, p.dot(cam.up));
    }
  }
  if (!(hi_x >= lo_x)) return img;
  const double span = std::max({hi_x - lo_x, (hi_y - lo_y) * opt.width / opt.height, 1e-9});
  const double scale = 0.92 * opt.width / span;
  const double cx = 0.5 * (lo_x + hi_x), cy = 0.5 * (lo_y + hi_y);
  std::vector<double> depth(static_cast<std::size_t>(opt.width) * opt.height, INFINITY);
  const Vec3 light = (-cam.forward + 0.6 * cam.up + 0.3 * cam.right).normalized();
  for (const RenderMesh& m : meshes) {
    const auto& x = *m.positions;
    for (const Face& f : *m.faces) {
      const Vec3 &a = x[f[0]], &b = x[f[1]], &c = x[f[2]];
      Vec3 n = (b - a).cross(c - a);
      if (!(n.norm() > 0) || !n.allFinite()) continue;
      n.normalize();
      const double shade = 0.25 + 0.75 * std::abs(n.dot(light));  // two-sided: cloth has no inside
      std::array<double, 3> sx{}, sy{}, sz{};
      for (int k = 0; k < 3; ++k) {
        const Vec3& p = x[f[k]];
        sx[k] = 0.5 * opt.width + (p.dot(cam.right) - cx) * scale;
        sy[k] = 0.5 * opt.height - (p.dot(cam.up) - cy) * scale;
        sz[k] = p.dot(cam.forward);
      }
      const double area = (sx[1] - sx[0]) * (sy[2] - sy[0]) - (sx[2] - sx[0]) * (sy[1] - sy[0]);
      if (std::abs(area) < 1e-12) continue;
      const int x0 = std::max(0, static_cast<int>(std::floor(std::min({sx[0], sx[1], sx[2]}))));
      const int x1 =
          std::min(opt.width - 1, static_cast<int>(std::ceil(std::max({sx[0], sx[1], sx[2]}))));
      const int y0 = std::max(0, static_cast<int>(std::floor(std::min({sy[0], sy[1], sy[2]}))));
      const int y1 =
          std::min(opt.height - 1, static_cast<int>(std::ceil(std::max({sy[0], sy[1], sy[2]}))));
      for (int py = y0; py <= y1; ++py) {
        for (int px = x0; px <= x1; ++px) {
          const double qx = px + 0.5, qy = py + 0.5;
          // Barycentric weights from edge functions.
          const double w0 = ((sx[1] - qx) * (sy[2] - qy) - (sx[2] - qx) * (sy[1] - qy)) / area;
          const double w1 = ((sx[2] - qx) * (sy[0] - qy) - (sx[0] - qx) * (sy[2] - qy)) / area;
          const double w2 = 1.0 - w0 - w1;
          if (w0 < 0 || w1 < 0 || w2 < 0) continue;
          const double z = w0 * sz[0] + w1 * sz[1] + w2 * sz[2];
          const std::size_t i = static_cast<std::size_t>(py) * opt.width + px;
          if (z >= depth[i]) continue;
          depth[i] = z;
          for (int ch = 0; ch < 3; ++ch) {
            img.rgb[3 * i + ch] =
                static_cast<unsigned char>(std::clamp(255.0 * m.color[ch] * shade, 0.0, 255.0));
          }
        }
      }
    }
  }
  return img;
}

// libpng encodes into memory; the bytes then go through the atomic writer like every output.
void write_png(const std::filesystem::path& path, const Image& img) {
  if (img.width <= 0 || img.height <= 0 ||
      img.rgb.size() != static_cast<std::size_t>(img.width) * img.height * 3) {
    throw std::invalid_argument(
        fmt::format("write_png: {}x{} image with {} bytes", img.width, img.height, img.rgb.size()));
  }
  std::string bytes;
  std::string error;
  png_structp png = png_create_write_struct(
      PNG_LIBPNG_VER_STRING, &error,
      [](png_structp p, png_const_charp msg) {
        *static_cast<std::string*>(png_get_error_ptr(p)) = msg;
        png_longjmp(p, 1);
      },
      nullptr);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    throw OutputError(fmt::format("cannot write '{}': libpng: out of memory", path.string()));
  }
  std::vector<png_const_bytep> rows(img.height);
  for (int y = 0; y < img.height; ++y)
    rows[y] = img.rgb.data() + static_cast<std::size_t>(y) * img.width * 3;
  // No C++ object with a destructor is created between setjmp and the last libpng call.
  if (setjmp(png_jmpbuf(png)) != 0) {
    png_destroy_write_struct(&png, &info);
    throw OutputError(fmt::format("cannot write '{}': libpng: {}", path.string(), error));
  }
  png_set_write_fn(
      png, &bytes,
      [](png_structp p, png_bytep data, png_size_t n) {
        static_cast<std::string*>(png_get_io_ptr(p))->append(reinterpret_cast<char*>(data), n);
      },
      nullptr);
  png_set_IHDR(png, info, static_cast<png_uint_32>(img.width), static_cast<png_uint_32>(img.height),
               8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_write_image(png, const_cast<png_bytepp>(rows.data()));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  write_file_atomic(path, bytes);
}

}  // namespace clothcd::sim

// Orthographic z-buffer rasterizer and a minimal PNG encoder (stored deflate blocks).
#include "clothcd/sim/render.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

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

std::uint32_t crc32(const unsigned char* data, std::size_t n, std::uint32_t crc = 0) {
  static const auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k)
        c = (c & 1u) != 0 ? 0xedb88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  crc = ~crc;
  for (std::size_t i = 0; i < n; ++i)
    crc = table[(crc ^ data[i]) & 0xffu] ^ (crc >> 8);
  return ~crc;
}

void put32(std::vector<unsigned char>& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8)
    out.push_back(static_cast<unsigned char>((v >> s) & 0xffu));
}

void chunk(std::vector<unsigned char>& out, const char* type,
           const std::vector<unsigned char>& data) {
  put32(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data.begin(), data.end());
  put32(out, crc32(out.data() + start, out.size() - start));
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

void write_png(const std::filesystem::path& path, const Image& img) {
  std::vector<unsigned char> raw;
  const std::size_t row = static_cast<std::size_t>(img.width) * 3;
  raw.reserve((row + 1) * img.height);
  for (int y = 0; y < img.height; ++y) {
    raw.push_back(0);  // filter: none
    raw.insert(raw.end(), img.rgb.begin() + static_cast<std::ptrdiff_t>(y * row),
               img.rgb.begin() + static_cast<std::ptrdiff_t>((y + 1) * row));
  }
  // zlib stream of stored blocks, then Adler-32 of the raw bytes.
  std::vector<unsigned char> z{0x78, 0x01};
  std::size_t pos = 0;
  do {
    const std::size_t len = std::min<std::size_t>(65535, raw.size() - pos);
    const bool last = pos + len == raw.size();
    z.push_back(last ? 1 : 0);
    z.push_back(static_cast<unsigned char>(len & 0xffu));
    z.push_back(static_cast<unsigned char>(len >> 8));
    z.push_back(static_cast<unsigned char>(~len & 0xffu));
    z.push_back(static_cast<unsigned char>((~len >> 8) & 0xffu));
    z.insert(z.end(), raw.begin() + static_cast<std::ptrdiff_t>(pos),
             raw.begin() + static_cast<std::ptrdiff_t>(pos + len));
    pos += len;
  } while (pos < raw.size());
  std::uint32_t s1 = 1, s2 = 0;
  for (unsigned char b : raw) {
    s1 = (s1 + b) % 65521u;
    s2 = (s2 + s1) % 65521u;
  }
  put32(z, (s2 << 16) | s1);
  std::vector<unsigned char> png{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<unsigned char> ihdr;
  put32(ihdr, static_cast<std::uint32_t>(img.width));
  put32(ihdr, static_cast<std::uint32_t>(img.height));
  ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0});  // 8-bit RGB, deflate, no filter, no interlace
  chunk(png, "IHDR", ihdr);
  chunk(png, "IDAT", z);
  chunk(png, "IEND", {});
  write_file_atomic(path, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
}

}  // namespace clothcd::sim

#include "view/quantize.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace clothcd::view::detail {

QuantizedFrames quantize_frames(const std::vector<std::vector<Vec3>>& frames) {
  QuantizedFrames q;
  std::array<double, 3> lo, hi;
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  for (const auto& f : frames) {
    for (const Vec3& p : f) {
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], p[a]);
        hi[a] = std::max(hi[a], p[a]);
      }
    }
  }
  for (int a = 0; a < 3; ++a) {
    q.origin[a] = std::isfinite(lo[a]) ? lo[a] : 0.0;
    const double extent = std::isfinite(lo[a]) ? hi[a] - lo[a] : 0.0;
    q.step[a] = extent > 0.0 ? extent / 65535.0 : 1.0;
  }
  const std::size_t n = frames.empty() ? 0 : frames.front().size();
  q.low.resize(frames.size() * n * 3);
  q.high.resize(q.low.size());
  std::vector<std::uint16_t> previous(n * 3, 0);
  std::size_t at = 0;
  for (const auto& f : frames) {
    for (std::size_t v = 0; v < n; ++v) {
      for (int a = 0; a < 3; ++a, ++at) {
        const double t = std::round((f[v][a] - q.origin[a]) / q.step[a]);
        const auto value = static_cast<std::uint16_t>(std::clamp(t, 0.0, 65535.0));
        const auto diff = static_cast<std::uint16_t>(value - previous[v * 3 + a]);
        previous[v * 3 + a] = value;
        q.low[at] = static_cast<std::uint8_t>(diff & 0xffu);
        q.high[at] = static_cast<std::uint8_t>(diff >> 8);
      }
    }
  }
  return q;
}

Vec3 decoded_position(const QuantizedFrames& q, int num_vertices, int frame, int v) {
  Vec3 p;
  for (int a = 0; a < 3; ++a) {
    std::uint16_t value = 0;
    for (int k = 0; k <= frame; ++k) {
      const std::size_t at = (static_cast<std::size_t>(k) * num_vertices + v) * 3 + a;
      value = static_cast<std::uint16_t>(value + (q.low[at] | (q.high[at] << 8)));
    }
    p[a] = q.origin[a] + value * q.step[a];
  }
  return p;
}

}  // namespace clothcd::view::detail

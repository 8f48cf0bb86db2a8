#include "view/quantize.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace clothcd::view::detail {
namespace {

// A difference modulo 2^16 read as a signed 16-bit number s, coded as 2s (s >= 0) or -2s - 1.
std::uint16_t zigzag(std::uint16_t d) {
  const int s = d < 0x8000u ? d : static_cast<int>(d) - 0x10000;
  return static_cast<std::uint16_t>(s >= 0 ? 2 * s : -2 * s - 1);
}

std::uint16_t unzigzag(std::uint16_t z) {
  const int s = (z & 1u) != 0 ? -static_cast<int>(z >> 1) - 1 : static_cast<int>(z >> 1);
  return static_cast<std::uint16_t>(s);
}

}  // namespace

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
  std::vector<std::uint16_t> previous(n * 3, 0), velocity(n * 3, 0);
  std::size_t at = 0;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    for (std::size_t v = 0; v < n; ++v) {
      for (int a = 0; a < 3; ++a, ++at) {
        const std::size_t i = v * 3 + a;
        const double t = std::round((frames[k][v][a] - q.origin[a]) / q.step[a]);
        const auto value = static_cast<std::uint16_t>(std::clamp(t, 0.0, 65535.0));
        std::uint16_t code = value;
        if (k > 0) {
          const auto step = static_cast<std::uint16_t>(value - previous[i]);
          code = zigzag(static_cast<std::uint16_t>(step - velocity[i]));
          velocity[i] = step;
        }
        previous[i] = value;
        q.low[at] = static_cast<std::uint8_t>(code & 0xffu);
        q.high[at] = static_cast<std::uint8_t>(code >> 8);
      }
    }
  }
  return q;
}

Vec3 decoded_position(const QuantizedFrames& q, int num_vertices, int frame, int v) {
  Vec3 p;
  for (int a = 0; a < 3; ++a) {
    std::uint16_t value = 0, velocity = 0;
    for (int k = 0; k <= frame; ++k) {
      const std::size_t at = (static_cast<std::size_t>(k) * num_vertices + v) * 3 + a;
      const auto code = static_cast<std::uint16_t>(q.low[at] | (q.high[at] << 8));
      if (k == 0) {
        value = code;
      } else {
        velocity = static_cast<std::uint16_t>(velocity + unzigzag(code));
        value = static_cast<std::uint16_t>(value + velocity);
      }
    }
    p[a] = q.origin[a] + value * q.step[a];
  }
  return p;
}

}  // namespace clothcd::view::detail

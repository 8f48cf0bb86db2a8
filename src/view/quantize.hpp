#pragma once
// Positions of a frame sequence as the page stores them: 16-bit integers q over the sequence's
// bounding box; frame 0 as is, frame 1 as its difference from frame 0, every later frame k as
// its difference from the straight-line guess q[k-1] + (q[k-1] - q[k-2]) (all modulo 2^16, so
// exact), each difference zigzag-coded (0, -1, 1, -2, ... as 0, 1, 2, 3, ...), the low bytes of
// all values before their high bytes. Most vertices move smoothly by a few quanta a frame, so
// nearly all high bytes are 0 and the data compresses well; the guess makes a body's frames
// about half as large and costs the cloth's nothing.

#include <array>
#include <cstdint>
#include <vector>

#include "view/page_builder.hpp"

namespace clothcd::view::detail {

struct QuantizedFrames {
  std::array<double, 3> origin{};  ///< x = origin + q * step, per axis
  std::array<double, 3> step{};
  std::vector<std::uint8_t> low, high;  ///< frames x vertices x 3 bytes each
};

[[nodiscard]] QuantizedFrames quantize_frames(const std::vector<std::vector<Vec3>>& frames);

/// Position of vertex v of frame k as the page decodes it (for tests).
[[nodiscard]] Vec3 decoded_position(const QuantizedFrames& q, int num_vertices, int frame, int v);

}  // namespace clothcd::view::detail

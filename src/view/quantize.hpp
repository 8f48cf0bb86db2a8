#pragma once
// Positions of a frame sequence as the page stores them: 16-bit integers over the sequence's
// bounding box, frame 0 as is and every later frame as the difference from the one before (modulo
// 2^16, so exact), the low bytes of all values before their high bytes. Between frames most
// vertices move by a few quanta, so the high bytes are nearly all 0 or 255 and the differences
// compress several times better than the positions.

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

// Conversion of a container size to a 32-bit index or offset that fails loudly: the mesh, BVH and
// detector store ids and CSR offsets as int, and a size past INT_MAX must be an error naming what
// overflowed, never a silent wrap.
#pragma once

#include <fmt/format.h>

#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string_view>

namespace clothcd::detail {

/// `size` as an int; throws std::length_error naming `what` when it exceeds INT_MAX.
inline int checked_int(std::size_t size, std::string_view what) {
  constexpr auto kMax = static_cast<std::size_t>(std::numeric_limits<int>::max());
  if (size > kMax) {
    throw std::length_error(
        fmt::format("{}: {} entries exceed the 32-bit index limit of {}", what, size, kMax));
  }
  return static_cast<int>(size);
}

}  // namespace clothcd::detail

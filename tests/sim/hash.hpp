#pragma once
// Bitwise hash of a position array, for determinism tests.

#include <cstdint>
#include <cstring>
#include <vector>

#include "clothcd/sim/elements.hpp"

namespace clothcd::sim::test {

inline std::uint64_t hash_positions(const std::vector<Vec3>& x) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a
  for (const Vec3& p : x) {
    for (int d = 0; d < 3; ++d) {
      std::uint64_t bits;
      std::memcpy(&bits, &p[d], sizeof bits);
      for (int k = 0; k < 8; ++k) {
        h ^= (bits >> (8 * k)) & 0xffu;
        h *= 1099511628211ull;
      }
    }
  }
  return h;
}

}  // namespace clothcd::sim::test

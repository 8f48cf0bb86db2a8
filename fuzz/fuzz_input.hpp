#pragma once
// Turns fuzzer bytes into doubles: finite values of every scale, plus the bit patterns as given
// (NaN, inf) when `raw` is set, so both the contract checks and the arithmetic get exercised.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace clothcd::fuzz {

class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  /// Next double from 8 bytes (zero-padded at the end).
  double raw_double() {
    unsigned char buf[8] = {};
    for (unsigned char& b : buf)
      b = pos_ < size_ ? data_[pos_++] : 0;
    double d;
    std::memcpy(&d, buf, sizeof d);
    return d;
  }

  /// A finite double: a raw one when finite, otherwise a small value from its low bits.
  double finite_double() {
    const double d = raw_double();
    if (std::isfinite(d)) return d;
    std::uint64_t bits;
    std::memcpy(&bits, &d, sizeof bits);
    return static_cast<double>(static_cast<std::int32_t>(bits & 0xffffffffu)) * 1e-6;
  }

  std::uint8_t byte() { return pos_ < size_ ? data_[pos_++] : 0; }
  [[nodiscard]] bool empty() const { return pos_ >= size_; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

}  // namespace clothcd::fuzz

#pragma once
// Adds the wall time of a scope to one of the collision stage's part times.

#include <chrono>

namespace clothcd::sim::detail {

class PartClock {
 public:
  explicit PartClock(double& into) : into_(into), start_(std::chrono::steady_clock::now()) {}
  ~PartClock() {
    into_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  PartClock(const PartClock&) = delete;
  PartClock& operator=(const PartClock&) = delete;

 private:
  double& into_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace clothcd::sim::detail

#pragma once
// Internal: a query as four moving points, rescaled by a power of two so that the largest
// coordinate lies in [0.5, 1). Scaling by 2^k is exact (bar subnormal underflow, which the error
// bounds absorb; coordinates that are all subnormal scale up exactly too), keeps every intermediate
// value far from overflow and underflow, and leaves the answer (contact yes/no, time of impact)
// unchanged.

#include <Eigen/Core>

#include <array>

namespace clothcd::ccd_detail {

/// Point order. VF: v, f0, f1, f2. EE: ea0, ea1, eb0, eb1.
enum class Kind { VertexFace, EdgeEdge };

struct Motion {
  std::array<Eigen::Vector3d, 4> x0, x1;  ///< positions at t = 0 and t = 1, scaled
  Eigen::Vector3d max_abs;                ///< per axis, largest |coordinate| after scaling
  double extent = 0;                      ///< largest coordinate range over the 8 points (scaled)
  double largest = 0;                     ///< largest |coordinate| before scaling
  int scale_exponent = 0;                 ///< the scale applied is 2^scale_exponent
  double scale = 1;  ///< 2^scale_exponent; 0 where that is above DBL_MAX (coordinates all
                     ///< below 2^-1023)
};

/// Builds the scaled motion; throws std::invalid_argument on NaN/inf coordinates.
Motion make_motion(const std::array<const Eigen::Vector3d*, 8>& points);

/// std::frexp's exponent of m (m = f 2^e, f in [0.5, 1)); 0 for m == 0.
int binade_exponent(double m);

/// 2^k (infinity above 2^1023).
double power_of_two(int k);

/// The scale make_motion applies for a largest |coordinate| m (finite, >= 0): 2^-e with m 2^-e in
/// [0.5, 1) (std::frexp's e), 1 for m == 0.
double inverse_binade(double m);

}  // namespace clothcd::ccd_detail

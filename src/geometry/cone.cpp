#include "clothcd/geometry/cone.hpp"

#include <numbers>

namespace clothcd {

bool NormalCone::saturated() const { return !(half_angle < std::numbers::pi / 2); }

}  // namespace clothcd

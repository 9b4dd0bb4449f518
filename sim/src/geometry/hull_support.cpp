// hull_support, until the hull builder's file (hull_build.cpp) brings its own definition: delete
// this file (and its line in sim/CMakeLists.txt) when that lands. The contract is hull.hpp's: the
// vertex farthest along the direction, ties to the lowest index.
#include <cstdint>

#include <detsim/fixed/vec3.hpp>

#include "hull.hpp"

namespace detsim::sim_detail {

std::uint16_t hull_support(const Hull& hull, Vec3 direction) noexcept {
  std::uint16_t best = 0;
  Fixed best_dot = Fixed::min();
  for (std::size_t i = 0; i < hull.vertices.size(); ++i) {
    const Fixed d = dot(hull.vertices[i], direction);
    if (i == 0 || d > best_dot) {
      best_dot = d;
      best = static_cast<std::uint16_t>(i);
    }
  }
  return best;
}

}  // namespace detsim::sim_detail

// The definitions of geometry that a World registers (World::create_heightfield,
// World::create_compound; World::create_convex_hull and World::create_mesh take plain spans).
#pragma once

#include <cstdint>
#include <vector>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/shape.hpp>

namespace detsim {

/// A grid of heights in the shape's local x-z plane: sample (row, column) is at
/// x = column * cell_size, z = row * cell_size, y = heights[row * columns + column]. Each cell is
/// two triangles split along the diagonal from (row, column) to (row + 1, column + 1). Static
/// bodies only.
struct HeightfieldDef {
  std::uint32_t rows = 0;     ///< samples along z, 2..4096
  std::uint32_t columns = 0;  ///< samples along x, 2..4096
  /// The spacing of samples (m), >= 2^-10, with (max(rows, columns) - 1) * cell_size <= 10^4.
  Fixed cell_size;
  std::vector<Fixed> heights;  ///< rows * columns, row-major, each within +-10^4 m

  friend bool operator==(const HeightfieldDef&, const HeightfieldDef&) = default;
};

/// One part of a compound: a primitive (sphere, box, capsule, cylinder) or a convex hull of the
/// same world, placed in the compound's frame.
struct CompoundChild {
  Shape shape;
  Vec3 position{};
  Quat orientation{};  ///< a unit quaternion

  friend constexpr bool operator==(const CompoundChild&, const CompoundChild&) noexcept = default;
};

}  // namespace detsim

// A static heightfield's geometry: what World::create_heightfield registers (once,
// content-hashed), and what static bodies' raycasts, overlaps and the narrowphase read, through
// the same triangle interface as a mesh (triangle_count, triangle, raycast, overlap). Internal to
// detsim::sim.
//
// The grid lies in the local x-z plane: sample (row, column) is the vertex
// (column * cell_size, heights[row * columns + column], row * cell_size). Cell (row, col), for
// row < rows - 1 and col < columns - 1, is split along its diagonal from sample (row, col) to
// sample (row + 1, col + 1) into two triangles, counter-clockwise seen from +y (normals up):
//   k = 0: (row, col), (row + 1, col), (row + 1, col + 1)
//   k = 1: (row, col), (row + 1, col + 1), (row, col + 1)
// and triangle index 2 * (row * (columns - 1) + col) + k. A mesh built from these triangles, in
// this order, has the same normals, edges and hits.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <detsim/core/bytes.hpp>
#include <detsim/core/status.hpp>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/geometry.hpp>

#include "triangle.hpp"

namespace detsim::sim_detail {

/// The most samples per side (rows, columns): up to 2 * 4095^2 triangles, and a height pyramid of
/// ~16 MB at that size.
inline constexpr std::uint32_t max_heightfield_side = 4096;
/// The smallest cell (m): twice a triangle's area, cell_size^2, stays above the degenerate
/// threshold of triangle_normal (2^-24 m^2).
inline constexpr Fixed min_heightfield_cell = Fixed::from_raw(Fixed::one_raw >> 10);

/// The public definition (detsim/sim/geometry.hpp), checked by build_heightfield.
using detsim::HeightfieldDef;

/// The heights of one level of the pyramid: per block of cells, the least and greatest height of
/// its samples. Level 0 has blocks of 4 x 4 cells; each level above merges 2 x 2 blocks, up to one.
struct HeightLevel {
  std::uint32_t block_rows = 0;
  std::uint32_t block_columns = 0;
  std::vector<Fixed> low;   ///< per block, row-major
  std::vector<Fixed> high;  ///< per block, row-major
  friend bool operator==(const HeightLevel&, const HeightLevel&) = default;
};

struct Heightfield {
  HeightfieldDef def;
  std::vector<HeightLevel> levels;  ///< the pyramid, level 0 (finest) first
  Bounds bounds;
  friend bool operator==(const Heightfield&, const Heightfield&) = default;
};

/// Checks `def` and builds the pyramid. Refuses, with a message naming the field: rows or columns
/// outside 2..4096, a heights count other than rows * columns, a cell_size below 2^-10 m or a grid
/// wider than 10^4 m, a height outside +-10^4 m (which includes the saturated Fixed::max()).
[[nodiscard]] Expected<Heightfield> build_heightfield(HeightfieldDef def);

[[nodiscard]] inline std::uint32_t triangle_count(const Heightfield& hf) noexcept {
  return 2 * (hf.def.rows - 1) * (hf.def.columns - 1);
}
/// The vertices of triangle `index` (< triangle_count), in the order of the file comment.
[[nodiscard]] std::array<Vec3, 3> triangle_vertices(const Heightfield& hf,
                                                    std::uint32_t index) noexcept;
/// Triangle `index` with its normal and edges (computed, as a mesh of the same triangles has them).
[[nodiscard]] TriangleData triangle(const Heightfield& hf, std::uint32_t index) noexcept;

/// The closest hit of the ray p + v t, 0 <= t <= max_t, as raycast(Mesh) (two-sided, ties to the
/// lower triangle index), found through the height pyramid.
[[nodiscard]] std::optional<TriangleHit> raycast(const Heightfield& hf, Vec3 p, Vec3 v,
                                                 Fixed max_t) noexcept;

/// The triangles whose bounds overlap the closed box [lo, hi], ascending, in `out` (cleared first).
void overlap(const Heightfield& hf, Vec3 lo, Vec3 hi, std::vector<std::uint32_t>& out);

/// The canonical encoding: a version byte (1), rows and columns (var32), cell_size (var_fixed), the
/// heights (var_fixed, row-major). read_heightfield rebuilds through build_heightfield.
void write(const Heightfield& hf, ByteWriter& w);
/// Reads what write wrote; refuses bad bytes with a message, checking the sample count against the
/// bytes left before allocating.
[[nodiscard]] Expected<Heightfield> read_heightfield(ByteReader& r);

}  // namespace detsim::sim_detail

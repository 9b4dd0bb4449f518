// What a viewer draws for a shape: one description for every shape type, in world space.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/shape.hpp>

namespace detsim {

/// A shape placed in the world, as a viewer draws it: the convex hull of `points` grown by
/// `radius` (a sphere: its centre and radius; a capsule: the two ends of its core and its radius;
/// a box: its eight corners, radius 0; a cylinder: 16 points on each end circle, radius 0), or, for
/// a plane (`half_space`), the solid below the plane through `points[0]` with outward unit normal
/// `normal`. A surface (a triangle mesh, a heightfield) is drawn as its `triangles` (world space,
/// in the geometry's triangle order, at most the first max_outline_triangles of them;
/// `surface_triangles` says how many it has), and its `points` are the eight corners of its local
/// bounding box (radius 0), for a viewer that draws only points.
/// A compound is drawn as its parts: `points` is empty and `parts` holds one outline per part (in
/// part order), each placed by the part's pose. For display only: nothing the
/// simulation computes depends on it.
struct ShapeOutline {
  bool half_space = false;
  std::vector<Vec3> points;
  Fixed radius{};
  Vec3 normal{};
  std::vector<std::array<Vec3, 3>> triangles;  ///< a surface's triangles; empty for a solid
  std::uint32_t surface_triangles = 0;         ///< all of a surface's triangles, drawn or not
  std::vector<ShapeOutline> parts;             ///< a compound's parts (empty for every other shape)
};

/// The most triangles an outline holds: a viewer's budget, not a limit of the geometry.
inline constexpr std::size_t max_outline_triangles = 20000;

/// The outline of `shape` at `position` with the unit quaternion `orientation`. A shape of a type
/// that does not exist gives an empty outline (no points).
[[nodiscard]] ShapeOutline shape_outline(const Shape& shape, Vec3 position, Quat orientation);

}  // namespace detsim

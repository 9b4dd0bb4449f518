// What a viewer draws for a shape: one description for every shape type, in world space.
#pragma once

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
/// `normal`. A compound is drawn as its parts: `points` is empty and `parts` holds one outline
/// per part (in part order), each placed by the part's pose. For display only: nothing the
/// simulation computes depends on it.
struct ShapeOutline {
  bool half_space = false;
  std::vector<Vec3> points;
  Fixed radius{};
  Vec3 normal{};
  std::vector<ShapeOutline> parts;  ///< a compound's parts (empty for every other shape)
};

/// The outline of `shape` at `position` with the unit quaternion `orientation`. A shape of a type
/// that does not exist gives an empty outline (no points).
[[nodiscard]] ShapeOutline shape_outline(const Shape& shape, Vec3 position, Quat orientation);

}  // namespace detsim

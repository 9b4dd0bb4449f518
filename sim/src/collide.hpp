// Narrowphase: contact manifolds between two posed shapes. Internal to detsim::sim.
//
// Conventions shared by every pair function and the solver:
// - A pair is (a, b) with a the body of lower ID. `normal` is a unit vector pointing from a into b:
//   moving b along +normal separates them.
// - Each point lies midway between the two surfaces; `separation` is the signed distance between
//   the surfaces along the normal at that point (negative when they overlap).
// - Points are reported while separation <= `margin` (speculative contacts), at most four per pair.
// - `feature` identifies the pair of features (vertex/edge/face indices of each shape) that made
//   the point, so that the solver can match a point with the same point of the previous step and
//   warm start it. It is stable while the same features touch, and depends only on the shapes'
//   features, never on the order in which points were found.
// - Everything is Fixed arithmetic and deterministic: no data-dependent iteration order, ties
//   broken by index.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <detsim/fixed/mat3.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/shape.hpp>

namespace detsim::sim_detail {

/// A body's placement for the narrowphase: position and the rotation matrix of its orientation
/// (to_mat3 of the unit quaternion), computed once per step.
struct Pose {
  Vec3 position;
  Mat3 rotation = Mat3::identity();
};

struct ContactPoint {
  Vec3 point;        ///< world space, midway between the surfaces
  Fixed separation;  ///< signed distance along the normal; < 0 when overlapping
  std::uint32_t feature = 0;
};

struct Manifold {
  Vec3 normal;  ///< unit, from a into b
  std::uint8_t count = 0;
  std::array<ContactPoint, 4> points{};
};

struct Geometry;

/// A shape placed for the narrowphase: the shape, the geometry it refers to (nullptr for a
/// primitive; see geometry/geometry.hpp) and its pose.
struct PosedShape {
  const Shape& shape;
  const Geometry* geometry;
  const Pose& pose;
};

/// The contact manifold of shape `a` against shape `b`, with every point whose separation is at
/// most `margin` (>= 0). `count` is 0 when the shapes are farther apart than `margin`, and always
/// 0 for a plane against a plane.
[[nodiscard]] Manifold collide(const PosedShape& a, const PosedShape& b, Fixed margin) noexcept;

/// A manifold between a sub-shape of a and one of b: a compound's part or a surface's triangle,
/// by index (0 for a whole shape).
struct SubManifold {
  std::uint32_t sub_a = 0;
  std::uint32_t sub_b = 0;
  Manifold manifold;
};

/// How many sub-shapes a shape has: a compound's parts, a surface's triangles, else 1.
[[nodiscard]] std::uint32_t sub_shape_count(const Shape& shape, const Geometry* g) noexcept;

/// Whether a shape has sub-shapes (a compound, a mesh, a heightfield): its pairs may make several
/// manifolds, one per pair of sub-shapes in touch.
[[nodiscard]] bool has_sub_shapes(const PosedShape& s) noexcept;

/// Whether a shape is a static surface of triangles (a mesh, a heightfield).
[[nodiscard]] bool has_triangles(const PosedShape& s) noexcept;

/// Manifolds of one part against a surface's triangles whose normals agree within this cosine
/// (about 1.3 degrees) are one patch of one face: collide_all merges them into one manifold, and
/// the narrowphase carries a patch's impulses from triangle to triangle by its normal.
inline constexpr Fixed surface_patch_cos = Fixed::from_raw(Fixed::one_raw - (Fixed::one_raw >> 12));

/// Every manifold with points between a sub-shape of `a` and one of `b` (margin as collide()),
/// ascending by (sub_a, sub_b), into `out` (cleared first). For two whole shapes it is collide()'s
/// manifold, as sub-shapes (0, 0), when it has points. Against a surface, each part's triangle
/// manifolds of one normal (surface_patch_cos) are merged into one of at most four points, keyed
/// by the patch's lowest triangle: a body on a floor of many triangles touches it as a plane.
void collide_all(const PosedShape& a, const PosedShape& b, Fixed margin,
                 std::vector<SubManifold>& out);

/// collide() for two primitives (shapes without geometry).
[[nodiscard]] inline Manifold collide(const Shape& a, const Pose& pose_a, const Shape& b,
                                      const Pose& pose_b, Fixed margin) noexcept {
  return collide(PosedShape{a, nullptr, pose_a}, PosedShape{b, nullptr, pose_b}, margin);
}

}  // namespace detsim::sim_detail

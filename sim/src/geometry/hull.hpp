// A convex hull's geometry: what the hull builder (hull_build.cpp) makes from a cloud of points,
// and what mass properties, rays, bounds and the convex narrowphase read. Internal to detsim::sim.
//
// Immutable once built. Everything is in the shape's local frame (the body's frame), in Fixed
// arithmetic, and a function of the input points' values only: the builder sorts and removes
// duplicate points first, so the same set of points in any order gives the same hull, bit for bit,
// on every platform.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/mat3.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>

namespace detsim::sim_detail {

/// The most points create_convex_hull accepts, and the most vertices a hull may keep. Input
/// beyond the first is refused; a hull whose build would keep more vertices than the second is
/// refused (simplify it first) — both bound the work and memory of every later query.
inline constexpr std::size_t max_hull_points = 4096;
inline constexpr std::size_t max_hull_vertices = 256;

/// One face: a convex polygon, its outward unit normal and plane offset (dot(normal, x) = offset
/// for x on the plane), and its vertices, counter-clockwise seen from outside, as the slice
/// [first, first + count) of Hull::face_vertices. Coplanar triangles are merged into one face.
struct HullFace {
  Vec3 normal;
  Fixed offset;
  std::uint16_t first = 0;
  std::uint16_t count = 0;
};

/// One edge, each stored once: vertices a < b, and the faces on either side.
struct HullEdge {
  std::uint16_t a = 0;
  std::uint16_t b = 0;
  std::uint16_t face_0 = 0;
  std::uint16_t face_1 = 0;
};

/// Mass properties of a solid of uniform density: volume, centroid, and the inertia tensor per
/// unit mass about the centroid (multiply by the mass), with its principal moments and axes.
struct SolidProperties {
  Fixed volume;           ///< m^3
  Vec3 centroid;          ///< local frame
  Mat3 inertia_per_mass;  ///< symmetric, about the centroid, local axes (m^2)
  Vec3 principal;         ///< the eigenvalues of inertia_per_mass (m^2)
  /// Rotation from the principal frame to the local frame: inertia_per_mass =
  /// R diag(principal) R^T with R = to_mat3(principal_axes). Identity when the tensor is diagonal.
  Quat principal_axes = Quat::identity();
};

struct Hull {
  std::vector<Vec3> vertices;  ///< ascending by (x, y, z) raw value; every one is a corner
  std::vector<HullFace> faces;
  std::vector<std::uint16_t> face_vertices;
  std::vector<HullEdge> edges;  ///< ascending by (a, b)
  SolidProperties solid;
  Vec3 aabb_min;  ///< local-frame bounds of the vertices
  Vec3 aabb_max;
  Fixed bounding_radius;  ///< max |vertex| (about the local origin, not the centroid)
  Fixed inner_radius;     ///< the smallest distance from the centroid to a face plane
};

/// Builds the hull of `points` (at most max_hull_points; components within +-10^4 m). Duplicate,
/// coplanar and interior points are fine. Refuses, with a message naming what is wrong: too many
/// points, fewer than 4 points that are not coplanar (a flat or degenerate cloud, including one
/// thinner than about a millimetre), or a hull with more than max_hull_vertices corners.
[[nodiscard]] Expected<Hull> build_hull(std::span<const Vec3> points);

/// The point of `hull` farthest along `direction` (any length, not zero); ties go to the lowest
/// vertex index, so the answer depends only on the hull and the direction.
[[nodiscard]] std::uint16_t hull_support(const Hull& hull, Vec3 direction) noexcept;

}  // namespace detsim::sim_detail

// A convex hull's geometry: what the hull builder (hull_build.cpp) makes from a cloud of points,
// and what mass properties, rays, bounds and the convex narrowphase read. Internal to detsim::sim.
//
// Immutable once built. Everything is in the shape's local frame (the body's frame), in Fixed
// arithmetic, and a function of the input points' values only: the builder sorts and removes
// duplicate points first, so the same set of points in any order gives the same hull, bit for bit,
// on every platform.
#pragma once

#include <array>
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

/// The thinnest cloud that makes a hull: 2^-10 m (about a millimetre). Points all within this of
/// one line or one plane (measured from the line or plane through the cloud's most spread points)
/// are refused as flat: such a solid's volume and inertia would be mostly rounding.
inline constexpr Fixed hull_min_thickness = Fixed::from_raw(Fixed::one_raw >> 10);

/// The builder's tolerance for a hull whose points span `extent` (the largest side of their
/// bounding box): 2^-20 m (about a micrometre) plus 2^-26 of the extent. A point within it of a
/// face's plane is on the face; triangles whose corners are within it of one plane are merged;
/// a point within it outside the hull may be left out (the hull is then that much smaller).
[[nodiscard]] constexpr Fixed hull_tolerance(Fixed extent) noexcept {
  return Fixed::from_raw(Fixed::one_raw >> 20) + (extent >> 26);
}

/// One face: a convex polygon, its outward unit normal and plane offset (dot(normal, x) = offset
/// for x on the plane), and its vertices, counter-clockwise seen from outside, as the slice
/// [first, first + count) of Hull::face_vertices. Coplanar triangles are merged into one face.
struct HullFace {
  Vec3 normal;
  Fixed offset;
  std::uint16_t first = 0;
  std::uint16_t count = 0;
};

/// One edge, each stored once: vertices a < b, and the faces on either side: face_0's loop runs
/// a -> b, face_1's runs b -> a.
struct HullEdge {
  std::uint16_t a = 0;
  std::uint16_t b = 0;
  std::uint16_t face_0 = 0;
  std::uint16_t face_1 = 0;
  Vec3 direction;  ///< normalize(vertices[b] - vertices[a]), made by the build
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
  /// hull_support's estimates of the vertices (raw >> 20 per component) and their largest
  /// magnitude, made by the build; empty for a hull made otherwise (hull_support makes them).
  std::vector<std::array<std::int64_t, 3>> coarse;
  std::int64_t coarse_widest = 0;
};

/// The volume, centroid and inertia of the solid bounded by `hull`'s faces (its vertices, faces
/// and face_vertices must be filled), by the divergence theorem (hull_mass.cpp). Refuses a solid
/// whose volume or moments would leave the Fixed range (a hull more than ~1290 m across).
[[nodiscard]] Expected<SolidProperties> solid_properties(const Hull& hull);

/// Builds the hull of `points` (at most max_hull_points; components within +-10^4 m). Duplicate,
/// coplanar and interior points are fine. Refuses, with a message naming what is wrong: too many
/// points, a component beyond +-10^4 m, fewer than 4 points that are not coplanar (a flat or
/// degenerate cloud, including one thinner than hull_min_thickness), a hull with more than
/// max_hull_vertices corners, or a solid too large for solid_properties. Every vertex of the
/// result is one of the points and a true corner (on at least three faces); every point is inside
/// the hull or within hull_tolerance of it.
[[nodiscard]] Expected<Hull> build_hull(std::span<const Vec3> points);

/// Fills hull.coarse and hull.coarse_widest from its vertices (build_hull does).
void make_coarse(Hull& hull);

/// The point of `hull` farthest along `direction` (any length, not zero); ties go to the lowest
/// vertex index, so the answer depends only on the hull and the direction.
[[nodiscard]] std::uint16_t hull_support(const Hull& hull, Vec3 direction) noexcept;

}  // namespace detsim::sim_detail

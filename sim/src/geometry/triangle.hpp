// One triangle of static geometry: the per-triangle tests that meshes (mesh.hpp) and heightfields
// (heightfield.hpp) share, and the view of a triangle the narrowphase reads from either. Internal
// to detsim::sim.
//
// Everything is in the shape's local frame, in Fixed arithmetic, and depends only on the values of
// the inputs: a mesh query and a brute-force loop over the same triangles call the same functions
// and so find the same hits.
//
// Ray precision. A ray is p + v t with v a unit vector and t >= 0 in metres. Geometry lies within
// +-10^4 m per component and p within +-2 * 10^4 m (query.cpp restarts a world ray just outside the
// shape's bounding sphere, which keeps it there): every intermediate below then stays far from the
// Fixed range (2^31), and the errors are a few ulps of the geometry's size.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/vec3.hpp>

namespace detsim::sim_detail {

/// The largest |coordinate| of a vertex or a height (m), as for every shape's size.
inline constexpr Fixed max_geometry_coordinate = Fixed::from_int(10000);

/// What lies across one edge of a triangle, for internal-edge contact handling. Part of the
/// geometry's meaning (never renumber, only append).
enum class EdgeKind : std::uint8_t {
  boundary = 0,  ///< no neighbour (an open edge, or one shared by more than two triangles)
  convex = 1,    ///< the neighbour bends away (a ridge): the edge is a real feature
  concave = 2,   ///< the neighbour bends up (a valley): contacts on the edge use the face normal
  flat = 3,      ///< the neighbour is coplanar (within 2^-11.5 rad): contacts use the face normal
};

/// The edge from vertex k to vertex (k + 1) % 3, seen from its triangle.
struct EdgeInfo {
  EdgeKind kind = EdgeKind::boundary;
  Vec3 neighbour_normal;  ///< the neighbour's unit normal; zero for a boundary edge
  /// Whether a contact on this edge must use the face normal instead of the edge's direction
  /// (the edge is internal and not a ridge), which removes "ghost" collisions on flat ground.
  [[nodiscard]] bool uses_face_normal() const noexcept {
    return kind == EdgeKind::flat || kind == EdgeKind::concave;
  }
  friend bool operator==(const EdgeInfo&, const EdgeInfo&) = default;
};

/// One triangle as the narrowphase sees it, from a mesh or a heightfield alike: its vertices
/// (counter-clockwise seen from the side its normal points to), its outward unit normal and its
/// three edges (edge k runs from vertices[k] to vertices[(k + 1) % 3]).
struct TriangleData {
  std::array<Vec3, 3> vertices;
  Vec3 normal;
  std::array<EdgeInfo, 3> edges;
  friend bool operator==(const TriangleData&, const TriangleData&) = default;
};

/// The closest hit of a ray on a mesh or a heightfield: the LocalHit of shapes.hpp plus the
/// triangle's index.
struct TriangleHit {
  Fixed t;      ///< metres along the unit direction
  Vec3 point;   ///< p + v t
  Vec3 normal;  ///< the triangle's unit normal, turned to face the ray's origin
  std::uint32_t triangle = 0;
  friend bool operator==(const TriangleHit&, const TriangleHit&) = default;
};

/// Whether `a` is the better of two hits: the lower t, ties to the lower triangle index. Every
/// raycast keeps its best hit by this order, so its answer does not depend on the visiting order.
[[nodiscard]] constexpr bool closer(const TriangleHit& a, const TriangleHit& b) noexcept {
  return a.t != b.t ? a.t < b.t : a.triangle < b.triangle;
}

/// The unit normal of the triangle (a, b, c), counter-clockwise: normalize((b - a) x (c - a)),
/// with the cross product taken exactly (no rounding) before normalizing, so that even a thin
/// sliver gets an accurate direction. nullopt for a degenerate triangle: one whose exact
/// (b - a) x (c - a) (twice its area) has no component of magnitude 2^-24 m^2 or more — zero area,
/// repeated or coincident vertices, and triangles too small to have a reliable normal.
[[nodiscard]] std::optional<Vec3> triangle_normal(Vec3 a, Vec3 b, Vec3 c) noexcept;

/// Whether the line p + v t (any t) passes through the closed triangle (a, b, c), from either side.
/// Watertight: each edge's side test is computed from its lexicographically lower endpoint (by the
/// coordinates' raw values), so two triangles sharing an edge compute exactly opposite values for
/// it, and a line through the shared edge crosses at least one of them. A line in the triangle's
/// plane crosses none.
[[nodiscard]] bool ray_crosses_triangle(Vec3 p, Vec3 v, Vec3 a, Vec3 b, Vec3 c) noexcept;

/// The t at which p + v t meets the plane through `a` with unit normal `n`, when 0 <= t <= max_t
/// and v is not parallel to the plane (dot(v, n) == 0 exactly); else nullopt.
[[nodiscard]] std::optional<Fixed> ray_plane_t(Vec3 p, Vec3 v, Vec3 a, Vec3 n,
                                               Fixed max_t) noexcept;

/// The hit of the ray on the plane through `a` with unit normal n (ray_plane_t), as the hit of
/// triangle `triangle` (its normal turned to face p); for a line known to cross that triangle.
[[nodiscard]] std::optional<TriangleHit> ray_hit_plane(Vec3 p, Vec3 v, Vec3 a, Vec3 n,
                                                       std::uint32_t triangle,
                                                       Fixed max_t) noexcept;

/// The ray p + v t, 0 <= t <= max_t, on the triangle (a, b, c) of unit normal n and index
/// `triangle`: ray_crosses_triangle, then ray_hit_plane. The one per-triangle test of every
/// raycast (two-sided).
[[nodiscard]] std::optional<TriangleHit> ray_triangle(Vec3 p, Vec3 v, Vec3 a, Vec3 b, Vec3 c,
                                                      Vec3 n, std::uint32_t triangle,
                                                      Fixed max_t) noexcept;

/// The kind of an edge from its triangle's unit normal `normal`, a point `on_edge` of the edge,
/// the neighbour's unit normal and the neighbour's vertex off the edge: flat when the normals are
/// within 2^-11.5 rad (dot >= 1 - 2^-24), else convex when that vertex lies below the triangle's
/// plane, concave when above.
[[nodiscard]] EdgeKind classify_edge(Vec3 normal, Vec3 on_edge, Vec3 neighbour_normal,
                                     Vec3 neighbour_far_vertex) noexcept;

/// The componentwise bounds of a triangle.
struct Bounds {
  Vec3 min;
  Vec3 max;
  friend bool operator==(const Bounds&, const Bounds&) = default;
};
[[nodiscard]] Bounds triangle_bounds(Vec3 a, Vec3 b, Vec3 c) noexcept;
/// Whether two closed boxes overlap (touching counts).
[[nodiscard]] constexpr bool overlaps(const Bounds& x, Vec3 lo, Vec3 hi) noexcept {
  return x.min.x <= hi.x && x.max.x >= lo.x && x.min.y <= hi.y && x.max.y >= lo.y &&
         x.min.z <= hi.z && x.max.z >= lo.z;
}

}  // namespace detsim::sim_detail

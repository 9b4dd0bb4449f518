// The generic convex narrowphase: one view over every convex shape (hull, box, sphere, capsule,
// cylinder) and the manifold of any two of them, or of one against a plane. Internal to
// detsim::sim; the pair table in collide.cpp calls it for the pairs that have no special function.
//
// Each view is a "core" swept by a sphere of `core_radius`: a sphere is a point + r, a capsule a
// segment + r, and a box, hull or cylinder is its own core with radius 0. Distances are taken
// between cores and the radii subtracted, so round shapes are exact (no polygonised spheres).
//
// Conventions are collide.hpp's: normal unit from a into b, points midway between the surfaces,
// separation along the normal, at most four points, every point within the margin.
//
// Feature IDs (ContactPoint::feature halves, collide_util.hpp): sphere, capsule and box use the
// primitives' IDs (so a box view names what box_box names). A hull names its face / edge / vertex
// by index (convex_feature, 14-bit indices). A cylinder (axis local y, caps at y = +-h) names
// face 0 its +y cap, face 1 its -y cap, edge 0 its side, vertex k (0 <= k < 16) the k-th point of
// the +y cap's rim polygon, 16 + k the -y cap's, 32 / 33 the -y / +y end of a side line, 34 / 35
// the exact support point on the -y / +y rim (a tilted cap's deepest point), and, from SAT only,
// edge 1 + k / 17 + k the +y / -y rim polygon's chord k and edge 33 + k the side line at point k.
#pragma once

#include <array>
#include <cstdint>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/shape.hpp>

#include "../collide.hpp"
#include "hull.hpp"
#include "triangle.hpp"

namespace detsim::sim_detail {

enum class ConvexKind : std::uint8_t { sphere, capsule, box, cylinder, hull };

/// A convex shape seen by the narrowphase: plain values, or a pointer to an immutable Hull that
/// must outlive the view. Build with the named constructors.
struct ConvexView {
  ConvexKind kind = ConvexKind::sphere;
  Fixed radius;       ///< sphere, capsule, cylinder (m)
  Fixed half_height;  ///< capsule core, cylinder (m)
  Vec3 half_extents;  ///< box (m)
  const Hull* hull = nullptr;

  [[nodiscard]] static constexpr ConvexView sphere(Fixed r) noexcept {
    return {ConvexKind::sphere, r, {}, {}, nullptr};
  }
  [[nodiscard]] static constexpr ConvexView capsule(Fixed r, Fixed half) noexcept {
    return {ConvexKind::capsule, r, half, {}, nullptr};
  }
  [[nodiscard]] static constexpr ConvexView box(Vec3 half) noexcept {
    return {ConvexKind::box, {}, {}, half, nullptr};
  }
  /// Radius r > 0, half height h > 0, axis the local y axis.
  [[nodiscard]] static constexpr ConvexView cylinder(Fixed r, Fixed half) noexcept {
    return {ConvexKind::cylinder, r, half, {}, nullptr};
  }
  [[nodiscard]] static constexpr ConvexView of_hull(const Hull& h) noexcept {
    return {ConvexKind::hull, {}, {}, {}, &h};
  }
  /// The view of a sphere, box, capsule or cylinder Shape (a plane has none: use convex_plane; a
  /// convex hull's is of_hull of its geometry).
  [[nodiscard]] static ConvexView of(const Shape& s) noexcept;
};

namespace convex {

/// Points of a cylinder cap's rim polygon (inscribed: every point is on the true rim).
inline constexpr unsigned cylinder_rim_points = 16;
/// The most vertices of a supporting face: a larger hull face keeps its first 32 loop vertices
/// (a convex sub-polygon, so the manifold stays inside the true contact patch).
inline constexpr unsigned max_face_points = 32;

/// A hull / cylinder feature half: collide_util's feature(kind, index) for index < 256, with
/// index bits 8..13 in bits 10..15 (a hull has at most 762 edges). Indices must be < 2^14.
[[nodiscard]] constexpr std::uint16_t convex_feature(unsigned kind_bits, unsigned index) noexcept {
  return static_cast<std::uint16_t>((index & 0xFFU) | (kind_bits << 8) |
                                    (((index >> 8) & 0x3FU) << 10));
}

/// The radius that sweeps the core: sphere and capsule radius, else 0.
[[nodiscard]] Fixed core_radius(const ConvexView& v) noexcept;

/// A point of the core and the feature that it is (a vertex, or the whole / an edge / a face of
/// the core when the direction does not pick one point).
struct SupportPoint {
  Vec3 point;
  std::uint16_t feature = 0;
};

/// The core's point farthest along `direction` (local frame, any length, zero allowed); ties go to
/// the lowest index / the +y side, so the answer depends only on the shape and the direction.
[[nodiscard]] SupportPoint core_support(const ConvexView& v, Vec3 direction) noexcept;

/// The point of the whole shape (core + radius) farthest along `direction` in world space.
[[nodiscard]] Vec3 support(const ConvexView& v, const Pose& pose, Vec3 direction) noexcept;

/// The core's face that most faces `direction`: a polygon (box or hull face, a cylinder cap's
/// rim polygon, counter-clockwise or clockwise), a segment (capsule core, cylinder side line) or
/// one point (sphere, a capsule end). `normal` is the polygon's outward unit normal (zero for
/// points and segments); `vertex` / `edge` name each point and the edge from it to the next.
struct Face {
  std::array<Vec3, max_face_points> points{};
  std::array<std::uint16_t, max_face_points> vertex{};
  std::array<std::uint16_t, max_face_points> edge{};
  unsigned count = 0;
  Vec3 normal;
  std::uint16_t feature = 0;  ///< the face (polygons), the edge (segments), the vertex (points)
};
/// In the local frame.
[[nodiscard]] Face supporting_face(const ConvexView& v, Vec3 direction) noexcept;
/// Posed: points and normal in world space relative to `origin`.
[[nodiscard]] Face supporting_face(const ConvexView& v, const Pose& pose, Vec3 direction,
                                   Vec3 origin) noexcept;

/// Face i of the core, for the separating axis test (local frame): its outward unit normal and
/// whether its normal is a true normal of the shape (a cylinder's prism sides are not).
struct SatFace {
  Vec3 normal;
  bool exact = true;
};
/// Edge i of the core, for the separating axis test (local frame): its ends, the normals of the
/// two faces beside it (the arc of its Gauss map), `circle` for a segment core (every normal
/// perpendicular to it), `exact` when it is an edge of the true shape.
struct SatEdge {
  Vec3 p0;
  Vec3 p1;
  Vec3 direction;  ///< unit, p0 -> p1
  Vec3 n0;
  Vec3 n1;
  std::uint16_t feature = 0;
  bool circle = false;
  bool exact = true;
};
[[nodiscard]] unsigned sat_face_count(const ConvexView& v) noexcept;
[[nodiscard]] SatFace sat_face(const ConvexView& v, unsigned i) noexcept;
[[nodiscard]] unsigned sat_edge_count(const ConvexView& v) noexcept;
[[nodiscard]] SatEdge sat_edge(const ConvexView& v, unsigned i) noexcept;

/// A bounding radius of the whole shape about its origin.
[[nodiscard]] Fixed bounding_radius(const ConvexView& v) noexcept;

/// The i-th rim direction (cos, sin) of a cylinder's polygon, at angle 2 pi i / 16 from local +x
/// towards local +z.
[[nodiscard]] Vec3 rim_direction(unsigned i) noexcept;

}  // namespace convex

/// The contact manifold of convex `a` at `pa` against convex `b` at `pb` (collide.hpp's
/// conventions; `margin` >= 0). Round cores and cylinders: GJK closest points while apart;
/// polytopes, and cores that meet: SAT over face normals and Gauss-map-pruned edge pairs (a
/// cylinder's 16-gon prism axes and its radial direction, measured with its true support), then
/// reference-face clipping reduced to four points. collide_convex(b, a) is collide_convex(a, b)
/// mirrored bit for bit (normal negated, feature halves swapped). Apart, every separation is a
/// lower bound of the distance (but for 2^-16 m on faces resting level). Iteration caps: GJK 32
/// steps, a cylinder's penetration refinement 16 rounds of 8 trials.
[[nodiscard]] Manifold collide_convex(const ConvexView& a, const Pose& pa, const ConvexView& b,
                                      const Pose& pb, Fixed margin) noexcept;

/// Convex `a` against the static half-space below `pb`'s local y = 0 plane (shape_plane.cpp);
/// normal = -up (from a into the plane). Polytopes: the deepest vertices within the margin,
/// reduced to four; cylinders: the cap rim polygon (plus the exact lowest rim point) or the side
/// line; round cores: their lowest core points less the radius.
[[nodiscard]] Manifold convex_plane(const ConvexView& a, const Pose& pa, const Pose& pb,
                                    Fixed margin) noexcept;

/// Convex `a` at `pa` against one triangle `tri` of a static surface (mesh or heightfield) posed
/// by `surface` (`tri` in the surface's frame): collide.hpp's conventions with the triangle as b,
/// so a body resting on a floor triangle gets normal ~ -(world face normal). At most four points,
/// every one within `margin` (>= 0).
/// - One-sided: the triangle bounds solid on its back side. No contact when a's centre (a hull's
///   bounding-box centre) lies behind the triangle's plane by more than the margin, and every
///   contact normal n_c points into the back side: dot(n_c, -face normal) >= 2^-16 (separating
///   axes that do not are only used to prove separation; a round core beside the triangle whose
///   closest-point normal does not is dropped). A box half through the triangle's interior gets
///   the face normal.
/// - Internal edges: a normal other than the face normal stays only when a contact point (before
///   reduction) has a real triangle feature (an edge that is boundary or convex, or a vertex with
///   such an edge beside it); otherwise (the face, flat or concave edges, their vertices) the
///   manifold takes -face normal, each point's pair of surface points projected on it (the
///   midpoint kept), points beyond the margin dropped.
/// - Features: a's as collide_convex names them; the triangle's face feature(face, 0), edge k
///   (vertex k -> k + 1) feature(edge, k), vertex k feature(vertex, k).
/// - Algorithm: round cores by closest points of the core and the triangle; polytopes and
///   cylinders by SAT over the face normal, a's face normals and Gauss-map-pruned edge pairs
///   (true supports), then the triangle (or a's face) as the reference face, clipped and
///   reduced as collide_convex does. Solved in a's frame, so poses within +-2^30 m are exact to
///   the geometry's ulps; no iteration.
[[nodiscard]] Manifold collide_triangle(const ConvexView& a, const Pose& pa,
                                        const TriangleData& tri, const Pose& surface,
                                        Fixed margin) noexcept;

}  // namespace detsim::sim_detail

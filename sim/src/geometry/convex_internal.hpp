// Internals shared by the convex narrowphase's files: a posed view relative to a common origin,
// GJK closest points, contact candidates and their reduction to four, and the manifold built from
// two supporting faces. Internal to the convex_*.cpp files.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/mat3.hpp>
#include <detsim/fixed/vec3.hpp>

#include "../collide.hpp"
#include "convex.hpp"

namespace detsim::sim_detail::convex {

/// A view posed relative to the pair's origin, so that every quantity below is bounded by the
/// shapes' sizes and their distance, never by world coordinates. collide_convex works in a's own
/// frame (a unrotated at the origin), as box_box does: b enters through one relative rotation.
struct Body {
  const ConvexView* view = nullptr;
  Mat3 rotation;
  Vec3 position;           ///< relative to the origin
  Fixed radius;            ///< core_radius(*view)
  Pose pose;               ///< the pose it was made from, for supporting_face
  Vec3 origin;             ///< the origin that positions are relative to
  bool unrotated = false;  ///< rotation is the identity (a pair solved in a's frame): no products
};

[[nodiscard]] Body make_body(const ConvexView& v, const Pose& pose, Vec3 origin) noexcept;

/// The core's support point relative to the origin, with its feature.
[[nodiscard]] SupportPoint support_at(const Body& b, Vec3 direction) noexcept;

/// The supporting face of b's core toward `direction`, relative to the origin.
[[nodiscard]] Face face_at(const Body& b, Vec3 direction) noexcept;

/// GJK (Gilbert-Johnson-Keerthi) closest points of the two cores: at most gjk_iterations support
/// steps, stopping when a step gains less than 2^-20 of |v|^2 (plus 2^-30 m^2), when a support
/// point repeats, or when |v| stops decreasing. `overlap` when the cores meet (|v| < 2^-20 m or the
/// origin inside a tetrahedron); then the points are meaningless.
inline constexpr int gjk_iterations = 32;
struct Closest {
  Vec3 on_a;
  Vec3 on_b;
  Fixed distance;
  bool overlap = false;
};
[[nodiscard]] Closest gjk_closest(const Body& a, const Body& b) noexcept;

/// A contact point before reduction: midway point (relative to the origin), separation, feature.
struct Candidate {
  Vec3 point;
  Fixed separation;
  std::uint32_t feature = 0;
};

/// Up to four of the candidates that keep the patch stable: the deepest, the farthest from it,
/// then the ones adding the most area on either side of that diagonal (Gregorius, "Robust Contact
/// Creation for Physics Simulations", GDC 2015). Ties go to the lower feature ID, so the result
/// depends on the features, not on the candidates' order. Writes into m (world: + origin).
void reduce_into(std::span<const Candidate> c, Vec3 normal, Vec3 origin, Manifold& m) noexcept;

/// A point of an incident face kept by a reference polygon's side planes, with the features whose
/// intersection it is (collide_convex's clipping, for callers with a face of their own: a
/// triangle of a static surface).
struct ClippedPoint {
  Vec3 point;
  std::uint16_t on_ref = 0;
  std::uint16_t on_inc = 0;
};
/// Clips `inc` (a polygon, a segment or a point) against the side planes of polygon `ref` (3 or
/// more points, either winding, `ref.normal` set); writes at most out.size() points, returns how
/// many.
[[nodiscard]] std::size_t clip_to_face(const Face& ref, const Face& inc,
                                       std::span<ClippedPoint> out) noexcept;

/// Which face the separating axis test chose as the reference, if any.
enum class Reference : std::uint8_t { any, a, b };

/// The manifold along normal n (a into b, unit) from the supporting faces of both cores:
/// polygon against polygon / segment / point by clipping against the reference polygon's side
/// planes, segment against segment by their overlap or closest points, else the two support
/// points. A reference polygon within ~0.3 degree of n gives its own normal (exact separations).
/// With `apart` (cores GJK found apart), two segments crossing between their ends refine n to
/// their common perpendicular. Candidates beyond the margin are dropped; with none, count is 0.
[[nodiscard]] Manifold manifold_from_faces(const Body& a, const Body& b, Vec3 n, Reference ref,
                                           Fixed margin, bool apart = false) noexcept;

/// One point from the closest points of the cores (on_a, on_b) along n: the fallback for contacts
/// no face produces.
[[nodiscard]] Manifold single_point(const Body& a, const Body& b, Vec3 on_a, Vec3 on_b, Vec3 n,
                                    std::uint32_t feature, Fixed margin) noexcept;

}  // namespace detsim::sim_detail::convex

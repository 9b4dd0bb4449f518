// Narrowphase internals shared by collide.cpp and collide_box.cpp: feature IDs, tolerances, small
// vector and box helpers, closest points of segments and the pair functions' declarations.
//
// Every pair function takes its shapes in the canonical order of ShapeType (sphere < box < capsule
// < plane); collide() swaps its arguments into that order and mirrors the result.
#pragma once

#include <array>
#include <cstdint>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/mat3.hpp>
#include <detsim/fixed/math.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/shape.hpp>

#include "collide.hpp"

namespace detsim::sim_detail::narrow {

// ---- Feature IDs --------------------------------------------------------------------------------
//
// ContactPoint::feature = (feature on a) | (feature on b) << 16, so mirroring a pair swaps the two
// halves. A half is kind << 8 | index:
// - sphere: the whole shape (kind whole, index 0);
// - capsule: vertex 0 is the core's -y end, vertex 1 its +y end, edge 0 the core segment;
// - plane: face 0;
// - box: face 2 axis + (negative ? 1 : 0); vertex bit i set when local coordinate i is +h_i; edge
//   4 axis + s1 + 2 s2, s1 / s2 set when coordinate (axis + 1) % 3 / (axis + 2) % 3 is positive.
// A contact made by clipping names the features whose intersection it is (an incident edge and a
// reference side edge, a reference corner and the incident face, ...), never its position in a
// list.

enum class Kind : std::uint16_t { whole = 0, vertex = 1, edge = 2, face = 3 };

[[nodiscard]] constexpr std::uint16_t feature(Kind kind, unsigned index) noexcept {
  return static_cast<std::uint16_t>((static_cast<unsigned>(kind) << 8) | (index & 0xFFU));
}
[[nodiscard]] constexpr std::uint32_t pair_feature(std::uint16_t on_a,
                                                   std::uint16_t on_b) noexcept {
  return static_cast<std::uint32_t>(on_a) | (static_cast<std::uint32_t>(on_b) << 16);
}
[[nodiscard]] constexpr std::uint32_t mirror_feature(std::uint32_t f) noexcept {
  return (f >> 16) | (f << 16);
}

/// Which side of the centre a box vertex or edge lies on, per local axis.
using Signs = std::array<bool, 3>;

[[nodiscard]] constexpr std::uint16_t box_face(int axis, bool positive) noexcept {
  return feature(Kind::face, static_cast<unsigned>(2 * axis + (positive ? 0 : 1)));
}
[[nodiscard]] constexpr std::uint16_t box_vertex(Signs s) noexcept {
  return feature(Kind::vertex, (s[0] ? 1U : 0U) | (s[1] ? 2U : 0U) | (s[2] ? 4U : 0U));
}
/// The edge along `axis`; s[axis] is ignored.
[[nodiscard]] constexpr std::uint16_t box_edge(int axis, Signs s) noexcept {
  const bool s1 = s[static_cast<unsigned>((axis + 1) % 3)];
  const bool s2 = s[static_cast<unsigned>((axis + 2) % 3)];
  return feature(Kind::edge, static_cast<unsigned>(4 * axis) + (s1 ? 1U : 0U) + (s2 ? 2U : 0U));
}

[[nodiscard]] constexpr Kind kind_of(std::uint16_t f) noexcept {
  return static_cast<Kind>(f >> 8);
}
[[nodiscard]] constexpr unsigned index_of(std::uint16_t f) noexcept {
  return f & 0xFFU;
}

inline constexpr std::uint16_t whole_shape = feature(Kind::whole, 0);
inline constexpr std::uint16_t plane_face = feature(Kind::face, 0);
inline constexpr std::uint16_t capsule_core = feature(Kind::edge, 0);
[[nodiscard]] constexpr std::uint16_t capsule_end(bool top) noexcept {
  return feature(Kind::vertex, top ? 1U : 0U);
}
/// The capsule feature at core parameter s in [-half, half] (vertex 0 wins when half == 0).
[[nodiscard]] constexpr std::uint16_t capsule_feature_at(Fixed s, Fixed half) noexcept {
  if (s <= -half) return capsule_end(false);
  if (s >= half) return capsule_end(true);
  return capsule_core;
}

// ---- Tolerances ---------------------------------------------------------------------------------
//
// Powers of two so that they are exact and need no literal parsing. Angles are compared through
// |u x v|^2 = sin^2 of the angle between unit vectors, which dot/cross compute exactly then round
// once, so even tiny angles are measured to the ulp.

/// Below this sin^2 (angle < ~1e-3 rad) two directions are parallel for closest-point solving: the
/// 2x2 system's determinant is sin^2, and dividing a numerator known to ~2^-32 |d| by less than
/// 2^-20 would leave the parameter with more than 2^-12 |d| of error. Also the threshold below
/// which box edge pairs are skipped as separating axes.
inline constexpr Fixed parallel_sin2 = Fixed::from_raw(Fixed::one_raw >> 20);
/// Below this sin^2 (angle < ~0.9 degree) two segments lying along each other get two contacts
/// (the ends of their overlap) instead of one, so that a capsule resting on another does not rock.
inline constexpr Fixed flat_sin2 = Fixed::from_raw(Fixed::one_raw >> 12);
/// A capsule-box normal within ~0.3 degree of a box face normal (|n_k| >= 1 - 2^-16) is snapped to
/// it and the core is clipped against that face: two points for a capsule lying on a box.
inline constexpr Fixed face_cos = Fixed::from_raw(Fixed::one_raw - (Fixed::one_raw >> 16));
/// Closest points closer than this (~1.5e-5 m) do not define a direction well (a unit vector from
/// a difference of a few ulps); such deep contacts use separating axes instead.
inline constexpr Fixed core_epsilon = Fixed::from_raw(Fixed::one_raw >> 16);

/// The bias of separating-axis choices (there is no state between frames, so no true hysteresis):
/// `challenger` replaces `incumbent` only when it is larger by a relative 1/32 plus an absolute
/// 2^-20 of `scale` (about a micrometre for metre-sized shapes), so that rounding noise and tiny
/// motions do not flip a near tie between frames.
[[nodiscard]] constexpr bool clearly_greater(Fixed challenger, Fixed incumbent,
                                             Fixed scale) noexcept {
  const Fixed tolerance = (abs(incumbent) >> 5) + (scale >> 20) + Fixed::epsilon();
  return challenger > incumbent + tolerance;
}

// ---- Vector helpers -----------------------------------------------------------------------------

[[nodiscard]] constexpr Fixed component(Vec3 v, int i) noexcept {
  return i == 0 ? v.x : (i == 1 ? v.y : v.z);
}
constexpr void set_component(Vec3& v, int i, Fixed value) noexcept {
  (i == 0 ? v.x : (i == 1 ? v.y : v.z)) = value;
}
[[nodiscard]] constexpr Vec3 axis_vector(int i, bool positive = true) noexcept {
  Vec3 v;
  set_component(v, i, positive ? Fixed::one() : -Fixed::one());
  return v;
}
[[nodiscard]] constexpr Vec3 abs_components(Vec3 v) noexcept {
  return {abs(v.x), abs(v.y), abs(v.z)};
}
/// v / 2 per component, rounded to nearest even: exact midpoints of relative vectors.
[[nodiscard]] constexpr Vec3 half(Vec3 v) noexcept {
  return {v.x >> 1, v.y >> 1, v.z >> 1};
}
/// The point midway between p and q, computed from their difference so that large coordinates do
/// not need extra range.
[[nodiscard]] constexpr Vec3 midpoint(Vec3 p, Vec3 q) noexcept {
  return p + half(q - p);
}
[[nodiscard]] constexpr Fixed signed_value(bool positive, Fixed x) noexcept {
  return positive ? x : -x;
}
/// R^T v: world direction or offset into the body frame of rotation R (exact dots, one rounding).
[[nodiscard]] constexpr Vec3 to_local(const Mat3& rotation, Vec3 v) noexcept {
  return {dot(rotation.column(0), v), dot(rotation.column(1), v), dot(rotation.column(2), v)};
}
/// A unit vector for a contact normal. Rotation columns are unit only to ~10 ulp; renormalising
/// keeps |n|^2 - 1 within 2 ulp so the solver can trust it. `fallback` is returned for zero.
[[nodiscard]] inline Vec3 unit_or(Vec3 v, Vec3 fallback) noexcept {
  return normalize_or(v, fallback);
}
/// A deterministic unit vector perpendicular to unit u: u x e, e the world axis least aligned with
/// u (ties to the lower axis), so the cross product has length >= sqrt(2/3).
inline Vec3 any_perpendicular(Vec3 u) noexcept {
  const Vec3 m = abs_components(u);
  int least = 0;
  if (m.y < component(m, least)) least = 1;
  if (m.z < component(m, least)) least = 2;
  return unit_or(cross(u, axis_vector(least)), Vec3::unit_x());
}

// ---- Boxes --------------------------------------------------------------------------------------

/// The point of the solid box [-h, h] closest to p (box frame), found by clamping each coordinate.
/// `clamped` counts the coordinates that moved: 0 inside, 1 on a face, 2 an edge, 3 a vertex;
/// `feature` names that face, edge or vertex (0 when inside).
struct BoxPoint {
  Vec3 point;
  std::uint16_t feature = 0;
  int clamped = 0;
};
[[nodiscard]] BoxPoint closest_box_point(Vec3 p, Vec3 h) noexcept;

/// A box-local manifold (normal and points in the box's frame) moved into world space.
inline Manifold to_world(Manifold m, const Pose& pose) noexcept {
  m.normal = unit_or(pose.rotation * m.normal, Vec3::unit_y());
  for (std::uint8_t i = 0; i < m.count; ++i) {
    m.points[i].point = pose.position + pose.rotation * m.points[i].point;
  }
  return m;
}

/// The largest half extent plus one metre: the scale of the axis-choice bias.
inline Fixed axis_bias_scale(Vec3 h) noexcept {
  return Fixed::one() + max(h.x, max(h.y, h.z));
}

// ---- Segments -----------------------------------------------------------------------------------

/// The segment center + direction s for s in [-half_length, half_length]; direction is unit (a
/// rotation column, unit to ~10 ulp), so parameters are lengths in metres and no division by
/// |direction|^2 is needed.
struct Segment {
  Vec3 center;
  Vec3 direction;
  Fixed half_length;

  [[nodiscard]] constexpr Vec3 at(Fixed s) const noexcept { return center + direction * s; }
};

struct SegmentParams {
  Fixed s;  ///< on the first segment
  Fixed t;  ///< on the second
};

/// One end of the overlap of segment a with the projection of a nearly parallel segment b onto
/// a's line: the parameter on a and which segment's end bounds it (both when they coincide).
struct OverlapEnd {
  Fixed s;
  bool a_end = false;
  bool b_end = false;
  bool b_top = false;  ///< which end of b (false: -half_length) when b_end
};

/// The overlap [lo.s, hi.s] on a of a and b's projection. True when it has positive length.
inline bool segment_overlap(const Segment& a, const Segment& b, OverlapEnd& lo,
                            OverlapEnd& hi) noexcept {
  const Fixed k = dot(a.direction, b.direction);
  const Fixed c = dot(a.direction, b.center - a.center);
  const Fixed reach = k * b.half_length;
  // b's ends projected on a's line: its -half end at c - reach, its +half end at c + reach.
  const bool reversed = reach < Fixed::zero();
  const Fixed b_low = reversed ? c + reach : c - reach;
  const Fixed b_high = reversed ? c - reach : c + reach;
  lo = OverlapEnd{max(-a.half_length, b_low), -a.half_length >= b_low, b_low >= -a.half_length,
                  reversed};
  hi = OverlapEnd{min(a.half_length, b_high), a.half_length <= b_high, b_high <= a.half_length,
                  !reversed};
  return lo.s < hi.s;
}

/// Parameters of a pair of closest points of two segments (Ericson, Real-Time Collision Detection
/// 5.1.9, with unit directions). Directions closer to parallel than parallel_sin2 take the middle
/// of the overlap of the first segment with the second's projection (or the nearest ends).
inline SegmentParams closest_on_segments(const Segment& a, const Segment& b) noexcept {
  // Minimise |a(s) - b(t)|^2 with unit directions: s = (c - k f) / (1 - k^2), t = k s - f, where
  // k = ua.ub, c = ua.r, f = ub.r, r = b.center - a.center. 1 - k^2 is taken as |ua x ub|^2,
  // which the exact cross product gives to full relative precision even for small angles.
  const Vec3 r = b.center - a.center;
  const Fixed k = dot(a.direction, b.direction);
  const Fixed c = dot(a.direction, r);
  const Fixed f = dot(b.direction, r);
  const Fixed denom = length_squared(cross(a.direction, b.direction));
  Fixed s;
  if (denom >= parallel_sin2) {
    s = clamp((c - k * f) / denom, -a.half_length, a.half_length);
  } else {
    // Parallel: every s in the overlap is equally close; the middle of it is symmetric and stable.
    OverlapEnd lo;
    OverlapEnd hi;
    if (segment_overlap(a, b, lo, hi) || lo.s == hi.s) {
      s = lo.s + ((hi.s - lo.s) >> 1);
    } else {
      s = clamp(c, -a.half_length, a.half_length);
    }
  }
  const Fixed t_free = k * s - f;
  const Fixed t = clamp(t_free, -b.half_length, b.half_length);
  // Ericson's second pass: when t had to be clamped, s is re-solved for the clamped t.
  if (t != t_free) s = clamp(k * t + c, -a.half_length, a.half_length);
  return {s, t};
}

/// The edge of a box along `axis` that is extreme in direction `toward` (box frame), as a segment
/// in the box frame, with the signs that name it (box_edge(axis, signs)).
struct BoxEdge {
  Segment segment;
  Signs signs;
};
inline BoxEdge supporting_edge(Vec3 h, int axis, Vec3 toward) noexcept {
  BoxEdge e{{{}, axis_vector(axis), component(h, axis)}, {}};
  for (int j = 0; j < 3; ++j) {
    const bool positive = component(toward, j) >= Fixed::zero();
    e.signs[static_cast<unsigned>(j)] = positive;
    if (j != axis) set_component(e.segment.center, j, signed_value(positive, component(h, j)));
  }
  return e;
}

// ---- Manifold assembly --------------------------------------------------------------------------

/// Appends a point when its separation is within the margin and there is room (pair functions
/// never produce more than four points after their own reduction).
constexpr void add_point(Manifold& m, Vec3 point, Fixed separation, std::uint32_t feature_id,
                         Fixed margin) noexcept {
  if (separation > margin || m.count >= m.points.size()) return;
  m.points[m.count] = ContactPoint{point, separation, feature_id};
  ++m.count;
}

// ---- Pair functions (canonical order) -----------------------------------------------------------

[[nodiscard]] Manifold sphere_sphere(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                                     Fixed margin) noexcept;
[[nodiscard]] Manifold sphere_box(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                                  Fixed margin) noexcept;
[[nodiscard]] Manifold sphere_capsule(const Shape& a, const Pose& pa, const Shape& b,
                                      const Pose& pb, Fixed margin) noexcept;
[[nodiscard]] Manifold sphere_plane(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                                    Fixed margin) noexcept;
[[nodiscard]] Manifold box_box(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                               Fixed margin) noexcept;
[[nodiscard]] Manifold box_capsule(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                                   Fixed margin) noexcept;
[[nodiscard]] Manifold box_plane(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                                 Fixed margin) noexcept;
[[nodiscard]] Manifold capsule_capsule(const Shape& a, const Pose& pa, const Shape& b,
                                       const Pose& pb, Fixed margin) noexcept;
[[nodiscard]] Manifold capsule_plane(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                                     Fixed margin) noexcept;

}  // namespace detsim::sim_detail::narrow

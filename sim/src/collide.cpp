// Narrowphase dispatch (one table row per pair of shape types) and the pairs with a round shape:
// sphere-sphere, sphere-box, sphere-capsule, sphere-plane, capsule-capsule, capsule-plane and
// box-capsule (the capsule's core segment against the box).
//
// Precision: every pair works in coordinates relative to one of the bodies, so positions of up to
// ~10^4 m only enter through one exact subtraction, and every quantity after that is bounded by
// the shapes' sizes. Distances come from length() (correctly rounded, no intermediate overflow);
// projections from dot() (exact products, one rounding).
#include <array>
#include <cstddef>
#include <cstdint>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/vec3.hpp>

#include "collide.hpp"
#include "collide_util.hpp"
#include "geometry/convex.hpp"
#include "geometry/geometry.hpp"

namespace detsim::sim_detail {

namespace narrow {

BoxPoint closest_box_point(Vec3 p, Vec3 h) noexcept {
  BoxPoint out{p, 0, 0};
  Signs sign{};
  int free_axis = 0;
  int clamped_axis = 0;
  for (int i = 0; i < 3; ++i) {
    const Fixed pi = component(p, i);
    const Fixed hi = component(h, i);
    const Fixed qi = clamp(pi, -hi, hi);
    set_component(out.point, i, qi);
    sign[static_cast<unsigned>(i)] = pi > Fixed::zero();
    if (qi != pi) {
      ++out.clamped;
      clamped_axis = i;
    } else {
      free_axis = i;
    }
  }
  if (out.clamped == 1)
    out.feature = box_face(clamped_axis, sign[static_cast<unsigned>(clamped_axis)]);
  if (out.clamped == 2) out.feature = box_edge(free_axis, sign);
  if (out.clamped == 3) out.feature = box_vertex(sign);
  return out;
}

namespace {

/// The capsule's core as a segment relative to `origin`.
Segment core_of(const Shape& capsule, const Pose& pose, Vec3 origin) noexcept {
  return {pose.position - origin, pose.rotation.column(1), capsule.half_height};
}

/// A normal for two segments whose closest points coincide: perpendicular to both when they cross,
/// else perpendicular to a; oriented along `toward` (b's centre seen from a's) when that decides.
Vec3 crossing_normal(Vec3 ua, Vec3 ub, Vec3 toward) noexcept {
  const Vec3 w = cross(ua, ub);
  const Vec3 n = length_squared(w) >= parallel_sin2 ? normalize(w) : any_perpendicular(ua);
  return dot(n, toward) < Fixed::zero() ? -n : n;
}

}  // namespace

Manifold sphere_sphere(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                       Fixed margin) noexcept {
  const Vec3 d = pb.position - pa.position;
  const Fixed separation = length(d) - a.radius - b.radius;
  if (separation > margin) return {};
  Manifold m;
  // Coincident centres have no direction: +y is as good as any and is the same on every machine.
  m.normal = unit_or(d, Vec3::unit_y());
  const Vec3 on_a = m.normal * a.radius;
  const Vec3 on_b = d - m.normal * b.radius;
  add_point(m, pa.position + midpoint(on_a, on_b), separation,
            pair_feature(whole_shape, whole_shape), margin);
  return m;
}

Manifold sphere_box(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                    Fixed margin) noexcept {
  const Vec3 h = b.half_extents;
  const Vec3 c = to_local(pb.rotation, pa.position - pb.position);  // sphere centre, box frame
  const BoxPoint closest = closest_box_point(c, h);
  Vec3 q = closest.point;
  Vec3 n;  // box frame, from the sphere into the box
  Fixed separation;
  std::uint16_t box_feature = 0;
  if (closest.clamped > 0) {
    const Vec3 v = q - c;
    separation = length(v) - a.radius;
    if (separation > margin) return {};
    n = normalize(v);
    box_feature = closest.feature;
  } else {
    // Centre inside: push out through the nearest face (faces in index order, ties to the first).
    int best_axis = 0;
    bool best_positive = true;
    Fixed best_depth = Fixed::max();
    for (int i = 0; i < 3; ++i) {
      for (const bool positive : {true, false}) {
        const Fixed depth = component(h, i) - signed_value(positive, component(c, i));
        if (depth < best_depth) {
          best_depth = depth;
          best_axis = i;
          best_positive = positive;
        }
      }
    }
    separation = -best_depth - a.radius;
    if (separation > margin) return {};  // only with a negative margin
    n = axis_vector(best_axis, !best_positive);
    set_component(q, best_axis, signed_value(best_positive, component(h, best_axis)));
    box_feature = box_face(best_axis, best_positive);
  }
  Manifold m;
  m.normal = unit_or(pb.rotation * n, Vec3::unit_y());
  const Vec3 local_point = midpoint(c + n * a.radius, q);
  add_point(m, pb.position + pb.rotation * local_point, separation,
            pair_feature(whole_shape, box_feature), margin);
  return m;
}

Manifold sphere_capsule(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                        Fixed margin) noexcept {
  const Segment core = core_of(b, pb, pa.position);  // relative to the sphere's centre
  const Fixed s = clamp(dot(-core.center, core.direction), -core.half_length, core.half_length);
  const Vec3 closest = core.at(s);
  const Fixed separation = length(closest) - a.radius - b.radius;
  if (separation > margin) return {};
  Manifold m;
  // Centre on the core: leave sideways, the shallowest way out of a capsule.
  m.normal = unit_or(closest, any_perpendicular(core.direction));
  const Vec3 on_a = m.normal * a.radius;
  const Vec3 on_b = closest - m.normal * b.radius;
  add_point(m, pa.position + midpoint(on_a, on_b), separation,
            pair_feature(whole_shape, capsule_feature_at(s, core.half_length)), margin);
  return m;
}

Manifold sphere_plane(const Shape& a, const Pose& pa, const Shape&, const Pose& pb,
                      Fixed margin) noexcept {
  const Vec3 up = unit_or(pb.rotation.column(1), Vec3::unit_y());
  const Fixed height = dot(pa.position - pb.position, up);  // of the centre above the plane
  const Fixed separation = height - a.radius;
  if (separation > margin) return {};
  Manifold m;
  m.normal = -up;  // a is above the plane; moving the plane down separates them
  const Vec3 on_a = -up * a.radius;
  const Vec3 on_b = -up * height;
  add_point(m, pa.position + midpoint(on_a, on_b), separation,
            pair_feature(whole_shape, plane_face), margin);
  return m;
}

Manifold capsule_capsule(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                         Fixed margin) noexcept {
  const Segment sa = core_of(a, pa, pa.position);
  const Segment sb = core_of(b, pb, pa.position);
  const Fixed radii = a.radius + b.radius;
  // Bounding spheres first: beyond them nothing below needs range.
  if (length(sb.center) - sa.half_length - sb.half_length - radii > margin) return {};

  const SegmentParams p = closest_on_segments(sa, sb);
  const Vec3 on_a = sa.at(p.s);
  const Vec3 v = sb.at(p.t) - on_a;
  const Fixed distance = length(v);
  const Fixed separation = distance - radii;
  if (separation > margin) return {};

  Manifold m;
  m.normal = distance > Fixed::zero() ? normalize(v)
                                      : crossing_normal(sa.direction, sb.direction, sb.center);

  // Nearly parallel cores lying along each other: one contact at each end of their overlap, each
  // with its own separation along the common normal, so the pair rests on a line, not a pivot.
  OverlapEnd lo;
  OverlapEnd hi;
  if (length_squared(cross(sa.direction, sb.direction)) < flat_sin2 &&
      segment_overlap(sa, sb, lo, hi)) {
    for (const bool top : {false, true}) {
      const OverlapEnd& end = top ? hi : lo;
      const Vec3 pa_end = sa.at(end.s);
      const Fixed t = clamp(dot(pa_end - sb.center, sb.direction), -sb.half_length, sb.half_length);
      const Vec3 pb_end = sb.at(t);
      const Fixed sep = dot(pb_end - pa_end, m.normal) - radii;
      const std::uint16_t fa = end.a_end ? capsule_end(top) : capsule_core;
      const std::uint16_t fb = end.b_end ? capsule_end(end.b_top) : capsule_core;
      const Vec3 point = midpoint(pa_end + m.normal * a.radius, pb_end - m.normal * b.radius);
      add_point(m, pa.position + point, sep, pair_feature(fa, fb), margin);
    }
    // Slightly skewed cores can be closest between the ends while both ends are beyond the
    // margin: then the single closest point below is the contact.
    if (m.count > 0) return m;
  }

  const Vec3 point = midpoint(on_a + m.normal * a.radius, on_a + v - m.normal * b.radius);
  add_point(m, pa.position + point, separation,
            pair_feature(capsule_feature_at(p.s, sa.half_length),
                         capsule_feature_at(p.t, sb.half_length)),
            margin);
  return m;
}

Manifold capsule_plane(const Shape& a, const Pose& pa, const Shape&, const Pose& pb,
                       Fixed margin) noexcept {
  const Vec3 up = unit_or(pb.rotation.column(1), Vec3::unit_y());
  const Vec3 axis = pa.rotation.column(1);
  const Fixed centre_height = dot(pa.position - pb.position, up);
  const Fixed rise = dot(axis, up) * a.half_height;  // of the +y end above the centre
  Manifold m;
  m.normal = -up;
  for (const bool top : {false, true}) {
    if (top && a.half_height == Fixed::zero()) break;  // one end only: no duplicate point
    const Fixed height = top ? centre_height + rise : centre_height - rise;
    const Vec3 end = axis * signed_value(top, a.half_height);  // relative to the centre
    const Vec3 point = midpoint(end - up * a.radius, end - up * height);
    add_point(m, pa.position + point, height - a.radius, pair_feature(capsule_end(top), plane_face),
              margin);
  }
  return m;
}

// ---- Box-capsule --------------------------------------------------------------------------------

namespace {

/// Whether the closed segment meets the closed box [-h, h] (Liang-Barsky slab clipping).
bool segment_meets_box(const Segment& seg, Vec3 h) noexcept {
  Fixed lo = -seg.half_length;
  Fixed hi = seg.half_length;
  for (int i = 0; i < 3; ++i) {
    const Fixed u = component(seg.direction, i);
    const Fixed m = component(seg.center, i);
    const Fixed hb = component(h, i);
    if (u == Fixed::zero()) {
      if (abs(m) > hb) return false;
      continue;
    }
    Fixed s1 = (-hb - m) / u;  // saturates for tiny u, which still orders correctly
    Fixed s2 = (hb - m) / u;
    if (s2 < s1) {
      const Fixed tmp = s1;
      s1 = s2;
      s2 = tmp;
    }
    lo = max(lo, s1);
    hi = min(hi, s2);
    if (lo > hi) return false;
  }
  return true;
}

struct SegmentBoxClosest {
  Fixed s;  ///< on the core
  BoxPoint box;
};

/// Closest points of a segment outside a box. The minimum is attained at a segment end against
/// the box, or at the segment against one of the 12 edges: an interior segment point closest to
/// a face interior means the segment is parallel to that face, and sliding along it reaches an end
/// or an edge at the same distance. Candidates in a fixed order, the first strict minimum wins.
SegmentBoxClosest closest_segment_box(const Segment& core, Vec3 h) noexcept {
  SegmentBoxClosest best{};
  Fixed best_d2 = Fixed::max();
  for (const bool top : {false, true}) {
    const Fixed s = signed_value(top, core.half_length);
    const BoxPoint q = closest_box_point(core.at(s), h);
    const Fixed d2 = length_squared(core.at(s) - q.point);
    if (d2 < best_d2) {
      best_d2 = d2;
      best = {s, q};
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    for (unsigned corner = 0; corner < 4; ++corner) {
      Signs signs{};
      signs[static_cast<unsigned>((axis + 1) % 3)] = (corner & 1U) != 0;
      signs[static_cast<unsigned>((axis + 2) % 3)] = (corner & 2U) != 0;
      Vec3 center;
      for (int j = 0; j < 3; ++j) {
        if (j != axis) {
          set_component(center, j, signed_value(signs[static_cast<unsigned>(j)], component(h, j)));
        }
      }
      const Segment edge{center, axis_vector(axis), component(h, axis)};
      const SegmentParams p = closest_on_segments(core, edge);
      const Vec3 on_box = edge.at(p.t);
      const Fixed d2 = length_squared(core.at(p.s) - on_box);
      if (d2 < best_d2) {
        best_d2 = d2;
        std::uint16_t f = box_edge(axis, signs);
        if (p.t <= -edge.half_length || p.t >= edge.half_length) {
          signs[static_cast<unsigned>(axis)] = p.t > Fixed::zero();
          f = box_vertex(signs);
        }
        best = {p.s, {on_box, f, 2}};
      }
    }
  }
  return best;
}

/// The core clipped against the side planes of box face (k, positive): the part of the capsule
/// over that face, with one point at each end (two for a capsule lying on the face). Box frame.
Manifold capsule_on_face(const Segment& core, Vec3 h, Fixed radius, int k, bool positive,
                         Fixed margin) noexcept {
  Fixed lo = -core.half_length;
  Fixed hi = core.half_length;
  int lo_axis = -1;  // the side plane that clipped each end, if any
  int hi_axis = -1;
  bool lo_positive = false;
  bool hi_positive = false;
  for (const int j : {(k + 1) % 3, (k + 2) % 3}) {
    const Fixed u = component(core.direction, j);
    const Fixed m = component(core.center, j);
    const Fixed hj = component(h, j);
    if (u == Fixed::zero()) {
      if (abs(m) > hj) lo = Fixed::max();  // wholly beside the face
      continue;
    }
    const Fixed s_neg = (-hj - m) / u;  // where x_j = -h_j
    const Fixed s_pos = (hj - m) / u;
    const bool enter_positive = u < Fixed::zero();
    const Fixed enter = enter_positive ? s_pos : s_neg;
    const Fixed exit = enter_positive ? s_neg : s_pos;
    if (enter > lo) {
      lo = enter;
      lo_axis = j;
      lo_positive = enter_positive;
    }
    if (exit < hi) {
      hi = exit;
      hi_axis = j;
      hi_positive = !enter_positive;
    }
  }
  Manifold m;
  m.normal = axis_vector(k, positive);
  if (lo > hi) {
    // Rounding left nothing over the face: one point at the core's closest approach to it.
    const Fixed s = clamp(-dot(core.center, core.direction), -core.half_length, core.half_length);
    lo = s;
    hi = s;
    lo_axis = -1;
    hi_axis = -1;
  }
  const Fixed top = component(h, k);
  for (const bool upper : {false, true}) {
    if (upper && hi == lo) break;
    const Fixed s = upper ? hi : lo;
    const int clip_axis = upper ? hi_axis : lo_axis;
    const bool clip_positive = upper ? hi_positive : lo_positive;
    Vec3 p = core.at(s);
    std::uint16_t box_feature = box_face(k, positive);
    std::uint16_t cap_feature = capsule_feature_at(s, core.half_length);
    if (clip_axis >= 0) {
      set_component(p, clip_axis, signed_value(clip_positive, component(h, clip_axis)));
      Signs signs{};
      signs[static_cast<unsigned>(k)] = positive;
      signs[static_cast<unsigned>(clip_axis)] = clip_positive;
      box_feature = box_edge(3 - k - clip_axis, signs);
      cap_feature = capsule_core;
    }
    for (int j = 0; j < 3; ++j) {  // keep the box point on the face despite rounding
      if (j != k) set_component(p, j, clamp(component(p, j), -component(h, j), component(h, j)));
    }
    const Fixed separation = signed_value(positive, component(p, k)) - top - radius;
    Vec3 on_box = p;
    set_component(on_box, k, signed_value(positive, top));
    add_point(m, midpoint(on_box, p - m.normal * radius), separation,
              pair_feature(box_feature, cap_feature), margin);
  }
  return m;
}

/// A capsule core nearly parallel to a box edge and closest to it: the two ends of their overlap.
Manifold capsule_along_edge(const Segment& core, const Segment& edge, Signs edge_signs, int axis,
                            Vec3 normal, Fixed radius, Fixed margin) noexcept {
  Manifold m;
  m.normal = normal;
  OverlapEnd lo;
  OverlapEnd hi;
  if (!segment_overlap(edge, core, lo, hi)) return m;
  for (const bool upper : {false, true}) {
    const OverlapEnd& end = upper ? hi : lo;
    const Vec3 on_box = edge.at(end.s);
    const Fixed t =
        clamp(dot(on_box - core.center, core.direction), -core.half_length, core.half_length);
    const Vec3 on_core = core.at(t);
    Signs signs = edge_signs;
    signs[static_cast<unsigned>(axis)] = upper;
    const std::uint16_t fa = end.a_end ? box_vertex(signs) : box_edge(axis, edge_signs);
    const std::uint16_t fb = end.b_end ? capsule_end(end.b_top) : capsule_core;
    add_point(m, midpoint(on_box, on_core - normal * radius),
              dot(on_core - on_box, normal) - radius, pair_feature(fa, fb), margin);
  }
  return m;
}

/// Separating axes for a core that meets (or nearly meets) the box: the three face normals and
/// the three edge directions crossed with the core. These are the face normals of the Minkowski
/// difference of a box and a segment, so the largest separation is the penetration depth.
Manifold capsule_into_box(const Segment& core, Vec3 h, Fixed radius, Fixed margin) noexcept {
  int face = 0;
  Fixed sep_face = Fixed::min();
  for (int k = 0; k < 3; ++k) {
    const Fixed s = abs(component(core.center, k)) - component(h, k) -
                    core.half_length * abs(component(core.direction, k)) - radius;
    if (s > sep_face) {
      sep_face = s;
      face = k;
    }
  }
  int edge = -1;
  Vec3 edge_normal;
  Fixed sep_edge = Fixed::min();
  for (int k = 0; k < 3; ++k) {
    const Vec3 w = cross(axis_vector(k), core.direction);
    if (length_squared(w) < parallel_sin2) continue;
    Vec3 l = normalize(w);
    if (dot(l, core.center) < Fixed::zero()) l = -l;
    const Fixed s = dot(l, core.center) - dot(h, abs_components(l)) -
                    core.half_length * abs(dot(l, core.direction)) - radius;
    if (s > sep_edge) {
      sep_edge = s;
      edge = k;
      edge_normal = l;
    }
  }
  if (max(sep_face, sep_edge) > margin) return {};
  if (edge < 0 || !clearly_greater(sep_edge, sep_face, axis_bias_scale(h))) {
    return capsule_on_face(core, h, radius, face, component(core.center, face) >= Fixed::zero(),
                           margin);
  }
  const BoxEdge e = supporting_edge(h, edge, edge_normal);
  const SegmentParams p = closest_on_segments(core, e.segment);
  Manifold m;
  m.normal = edge_normal;
  add_point(m, midpoint(e.segment.at(p.t), core.at(p.s) - edge_normal * radius), sep_edge,
            pair_feature(box_edge(edge, e.signs), capsule_feature_at(p.s, core.half_length)),
            margin);
  return m;
}

}  // namespace

Manifold box_capsule(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                     Fixed margin) noexcept {
  const Vec3 h = a.half_extents;
  const Fixed radius = b.radius;
  const Vec3 d = pb.position - pa.position;
  if (length(d) - length(h) - b.half_height - radius > margin) return {};
  const Segment core{to_local(pa.rotation, d), to_local(pa.rotation, pb.rotation.column(1)),
                     b.half_height};

  if (!segment_meets_box(core, h)) {
    const SegmentBoxClosest closest = closest_segment_box(core, h);
    const Vec3 v = core.at(closest.s) - closest.box.point;  // from the box into the capsule
    const Fixed distance = length(v);
    if (distance > core_epsilon) {
      const Fixed separation = distance - radius;
      if (separation > margin) return {};
      const Vec3 n = normalize(v);
      const Vec3 mag = abs_components(n);
      int k = 0;
      if (mag.y > component(mag, k)) k = 1;
      if (mag.z > component(mag, k)) k = 2;
      if (component(mag, k) >= face_cos) {
        // Over a face: clip the core to it. When the closest point was just past the face's edge
        // (within the snapping angle) the clipped ends can be beyond the margin; then the single
        // closest point below is the contact.
        const Manifold on_face =
            capsule_on_face(core, h, radius, k, component(n, k) > Fixed::zero(), margin);
        if (on_face.count > 0) return to_world(on_face, pa);
      }
      if (kind_of(closest.box.feature) == Kind::edge) {
        const int axis = static_cast<int>(index_of(closest.box.feature) / 4);
        if (length_squared(cross(core.direction, axis_vector(axis))) < flat_sin2) {
          const BoxEdge e = supporting_edge(h, axis, closest.box.point);
          const Manifold along =
              capsule_along_edge(core, e.segment, e.signs, axis, n, radius, margin);
          if (along.count > 0) return to_world(along, pa);
        }
      }
      Manifold m;
      m.normal = n;
      add_point(m, midpoint(closest.box.point, core.at(closest.s) - n * radius), separation,
                pair_feature(closest.box.feature, capsule_feature_at(closest.s, core.half_length)),
                margin);
      return to_world(m, pa);
    }
  }
  return to_world(capsule_into_box(core, h, radius, margin), pa);
}

}  // namespace narrow

namespace {

using namespace narrow;

using PairFunction = Manifold (*)(const PosedShape& a, const PosedShape& b, Fixed margin) noexcept;

/// A pair function of two primitives (their fields are the whole shape) as a PairFunction.
using PrimitivePair = Manifold (*)(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                                   Fixed margin) noexcept;
template <PrimitivePair F>
Manifold primitive(const PosedShape& a, const PosedShape& b, Fixed margin) noexcept {
  return F(a.shape, a.pose, b.shape, b.pose, margin);
}

/// One row per pair of shape types that can touch, with a.type <= b.type: a new shape type adds
/// its rows here (and its pair functions). Pairs without a row have no manifold: two planes, which
/// are static and unbounded. Shapes with sub-shapes (compounds, surfaces) are taken apart before
/// this table (collide_parts.cpp).
struct PairRow {
  ShapeType a;
  ShapeType b;
  PairFunction collide;
};

// The generic convex narrowphase (geometry/convex.hpp) for the pairs with a cylinder or a convex
// hull: one view over every convex shape.
ConvexView view_of(const PosedShape& s) noexcept {
  return s.geometry != nullptr ? ConvexView::of_hull(s.geometry->hull()) : ConvexView::of(s.shape);
}

Manifold convex_pair(const PosedShape& a, const PosedShape& b, Fixed margin) noexcept {
  return collide_convex(view_of(a), a.pose, view_of(b), b.pose, margin);
}

// The plane is a (its type is below the cylinder's and the hull's): convex_plane's manifold,
// mirrored.
Manifold plane_convex(const PosedShape& a, const PosedShape& b, Fixed margin) noexcept {
  Manifold m = convex_plane(view_of(b), b.pose, a.pose, margin);
  m.normal = -m.normal;
  for (std::uint8_t i = 0; i < m.count; ++i)
    m.points[i].feature = mirror_feature(m.points[i].feature);
  return m;
}

constexpr PairRow kPairs[] = {
    {ShapeType::sphere, ShapeType::sphere, primitive<sphere_sphere>},
    {ShapeType::sphere, ShapeType::box, primitive<sphere_box>},
    {ShapeType::sphere, ShapeType::capsule, primitive<sphere_capsule>},
    {ShapeType::sphere, ShapeType::plane, primitive<sphere_plane>},
    {ShapeType::box, ShapeType::box, primitive<box_box>},
    {ShapeType::box, ShapeType::capsule, primitive<box_capsule>},
    {ShapeType::box, ShapeType::plane, primitive<box_plane>},
    {ShapeType::capsule, ShapeType::capsule, primitive<capsule_capsule>},
    {ShapeType::capsule, ShapeType::plane, primitive<capsule_plane>},
    {ShapeType::sphere, ShapeType::cylinder, convex_pair},
    {ShapeType::box, ShapeType::cylinder, convex_pair},
    {ShapeType::capsule, ShapeType::cylinder, convex_pair},
    {ShapeType::plane, ShapeType::cylinder, plane_convex},
    {ShapeType::cylinder, ShapeType::cylinder, convex_pair},
    {ShapeType::sphere, ShapeType::convex, convex_pair},
    {ShapeType::box, ShapeType::convex, convex_pair},
    {ShapeType::capsule, ShapeType::convex, convex_pair},
    {ShapeType::plane, ShapeType::convex, plane_convex},
    {ShapeType::cylinder, ShapeType::convex, convex_pair},
    {ShapeType::convex, ShapeType::convex, convex_pair},
};

/// kPairs as a table indexed by the two type values, which stay below kTypeLimit.
constexpr std::size_t kTypeLimit = 16;

constexpr bool types_in_range() {
  for (const PairRow& row : kPairs) {
    if (static_cast<std::size_t>(row.a) >= kTypeLimit ||
        static_cast<std::size_t>(row.b) >= kTypeLimit)
      return false;
  }
  return true;
}
static_assert(types_in_range(), "raise kTypeLimit");

struct PairTable {
  std::array<std::array<PairFunction, kTypeLimit>, kTypeLimit> at{};
  constexpr PairTable() {
    for (const PairRow& row : kPairs)
      at[static_cast<std::size_t>(row.a)][static_cast<std::size_t>(row.b)] = row.collide;
  }
};

constexpr PairTable kPairTable;

}  // namespace

Manifold collide(const PosedShape& a, const PosedShape& b, Fixed margin) noexcept {
  const auto ta = static_cast<std::size_t>(a.shape.type);
  const auto tb = static_cast<std::size_t>(b.shape.type);
  if (ta >= kTypeLimit || tb >= kTypeLimit) return {};
  if (ta <= tb) {
    const PairFunction f = kPairTable.at[ta][tb];
    return f != nullptr ? f(a, b, margin) : Manifold{};
  }
  // The pair function sees (b, a): mirror its manifold. Points and separations are symmetric; the
  // normal flips and each feature ID swaps its halves, so the low half still names a's feature.
  const PairFunction f = kPairTable.at[tb][ta];
  if (f == nullptr) return {};
  Manifold m = f(b, a, margin);
  m.normal = -m.normal;
  for (std::uint8_t i = 0; i < m.count; ++i) {
    m.points[i].feature = mirror_feature(m.points[i].feature);
  }
  return m;
}

}  // namespace detsim::sim_detail

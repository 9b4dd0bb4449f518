// The convex narrowphase's manifold from two supporting faces (the idea of Jolt's
// ManifoldBetweenTwoFaces): Sutherland-Hodgman clipping of the incident face against the side
// planes of the reference polygon, Liang-Barsky clipping of a segment, the overlap of two nearly
// parallel segments, else their closest points; then reduction to four points.
//
// Feature IDs name the features whose intersection a point is, as in collide_box.cpp: an incident
// vertex against the reference face, an incident edge through a reference side edge, a reference
// corner against the incident face; never a position in a list.
#include <array>
#include <cstdint>
#include <span>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/vec3.hpp>

#include "../collide_util.hpp"
#include "convex_internal.hpp"

namespace detsim::sim_detail::convex {

namespace manifold_detail {

using namespace narrow;

bool beats(Fixed value, std::uint32_t id, Fixed best, std::uint32_t best_id) noexcept {
  return value > best || (value == best && id < best_id);
}

Fixed area(Vec3 p, Vec3 q, Vec3 s, Vec3 normal) noexcept {
  return dot(cross(q - p, s - p), normal);
}

constexpr std::size_t kMaxCandidates = 2 * max_face_points;

/// One vertex of the clipped incident polygon; `in_*` describe the polygon edge ending here.
struct ClipVertex {
  Vec3 p;
  std::uint16_t on_ref = 0;
  std::uint16_t on_inc = 0;
  bool in_on_plane = false;
  unsigned in_plane = 0;
  std::uint16_t in_edge = 0;
};

struct Polygon {
  std::array<ClipVertex, kMaxCandidates> v{};
  unsigned n = 0;
  void emit(const ClipVertex& x) noexcept {
    if (n < v.size()) v[n++] = x;
  }
};

/// The reference polygon's side planes: outward unit normals and offsets.
struct SidePlanes {
  std::array<Vec3, max_face_points> normal{};
  std::array<Fixed, max_face_points> offset{};
  unsigned n = 0;
};

SidePlanes side_planes(const Face& ref) noexcept {
  SidePlanes s;
  Vec3 centroid;
  for (unsigned i = 0; i < ref.count; ++i)
    centroid += ref.points[i] / Fixed::from_int(static_cast<std::int32_t>(ref.count));
  for (unsigned q = 0; q < ref.count; ++q) {
    const Vec3 p = ref.points[q];
    Vec3 side = normalize(cross(ref.points[(q + 1) % ref.count] - p, ref.normal));
    if (dot(side, centroid - p) > Fixed::zero()) side = -side;  // either winding works
    s.normal[q] = side;
    s.offset[q] = dot(side, p);
  }
  s.n = ref.count;
  return s;
}

/// The reference corner where side planes q and q2 meet (adjacent edges share a vertex).
std::uint16_t ref_corner(const Face& ref, unsigned q, unsigned q2) noexcept {
  if (q2 == (q + 1) % ref.count) return ref.vertex[q2];
  return ref.vertex[q];
}

/// One Sutherland-Hodgman pass against side plane q (on the plane counts as inside).
void clip_pass(const Polygon& in, const SidePlanes& s, unsigned q, const Face& ref,
               std::uint16_t inc_face, Polygon& out) noexcept {
  out.n = 0;
  const auto height = [&](const ClipVertex& x) { return dot(s.normal[q], x.p) - s.offset[q]; };
  const auto crossing = [&](const ClipVertex& p, const ClipVertex& e) {
    const Fixed hp = height(p);
    const Fixed t = hp / (hp - height(e));  // exactly one end is outside: in [0, 1]
    ClipVertex x = e;
    x.p = p.p + (e.p - p.p) * t;
    if (e.in_on_plane) {
      x.on_ref = ref_corner(ref, q, e.in_plane);
      x.on_inc = inc_face;
    } else {
      x.on_ref = ref.edge[q];
      x.on_inc = e.in_edge;
    }
    return x;
  };
  for (unsigned i = 0; i < in.n; ++i) {
    const ClipVertex& p = in.v[i];
    const ClipVertex& e = in.v[(i + 1) % in.n];
    const bool p_in = height(p) <= Fixed::zero();
    const bool e_in = height(e) <= Fixed::zero();
    if (p_in && e_in) {
      out.emit(e);
    } else if (p_in) {
      out.emit(crossing(p, e));
    } else if (e_in) {
      ClipVertex x = crossing(p, e);
      x.in_on_plane = true;
      x.in_plane = q;
      out.emit(x);
      out.emit(e);
    }
  }
}

/// A segment (Liang-Barsky) or a point against the side planes: the part inside all of them.
/// A kept end names itself against the reference face; a cut end, the segment against the
/// reference edge that cut it.
Polygon clip_segment(const Face& ref, const SidePlanes& s, const Face& inc) noexcept {
  Polygon poly;
  const Vec3 p0 = inc.points[0];
  const Vec3 p1 = inc.points[inc.count - 1];
  Fixed lo = Fixed::zero();
  Fixed hi = Fixed::one();
  std::uint16_t lo_ref = ref.feature;
  std::uint16_t hi_ref = ref.feature;
  for (unsigned q = 0; q < s.n; ++q) {
    const Fixed h0 = dot(s.normal[q], p0) - s.offset[q];
    const Fixed h1 = dot(s.normal[q], p1) - s.offset[q];
    if (h0 > Fixed::zero() && h1 > Fixed::zero()) return poly;
    if (h0 <= Fixed::zero() && h1 <= Fixed::zero()) continue;
    const Fixed t = h0 / (h0 - h1);  // exactly one end is outside: in [0, 1]
    if (h0 > Fixed::zero() && t > lo) {
      lo = t;
      lo_ref = ref.edge[q];
    } else if (h1 > Fixed::zero() && t < hi) {
      hi = t;
      hi_ref = ref.edge[q];
    }
  }
  if (lo > hi) return poly;
  const auto at = [&](Fixed t, std::uint16_t on_ref, std::uint16_t end) {
    const bool clipped = on_ref != ref.feature;
    poly.emit({p0 + (p1 - p0) * t, on_ref, clipped ? inc.feature : end, false, 0, 0});
  };
  at(lo, lo_ref, inc.vertex[0]);
  if (inc.count == 2 && hi > lo) at(hi, hi_ref, inc.vertex[1]);
  return poly;
}

/// The incident face's points inside the reference polygon's side planes.
Polygon clip_incident(const Face& ref, const Face& inc) noexcept {
  const SidePlanes s = side_planes(ref);
  if (inc.count < 3) return clip_segment(ref, s, inc);
  Polygon poly;
  for (unsigned i = 0; i < inc.count; ++i)
    poly.emit({inc.points[i], ref.feature, inc.vertex[i], false, 0,
               inc.edge[(i + inc.count - 1) % inc.count]});
  Polygon scratch;
  for (unsigned q = 0; q < s.n && poly.n > 0; ++q) {
    clip_pass(poly, s, q, ref, inc.feature, scratch);
    poly = scratch;
  }
  return poly;
}

/// A candidate from a pair of core points (on_a, on_b) along n.
Candidate candidate(const Body& a, const Body& b, Vec3 on_a, Vec3 on_b, Vec3 n,
                    std::uint32_t feature) noexcept {
  const Fixed separation = dot(on_b - on_a, n) - a.radius - b.radius;
  return {midpoint(on_a + n * a.radius, on_b - n * b.radius), separation, feature};
}

struct Candidates {
  std::array<Candidate, kMaxCandidates> c{};
  std::size_t n = 0;
  void add(const Candidate& x, Fixed margin) noexcept {
    if (x.separation <= margin && n < c.size()) c[n++] = x;
  }
};

/// Polygon reference within face_cos of n: clip, then measure each incident point's height above
/// the reference plane along the reference normal, which becomes the contact normal (exact
/// separations for faces resting on each other).
Vec3 clip_contacts(const Body& a, const Body& b, const Face& fa, const Face& fb, bool ref_is_a,
                   Fixed margin, Candidates& out) noexcept {
  const Face& ref = ref_is_a ? fa : fb;
  const Face& inc = ref_is_a ? fb : fa;
  const Vec3 n = ref_is_a ? ref.normal : -ref.normal;  // the ref normal, oriented a -> b
  const Fixed plane = dot(ref.normal, ref.points[0]);
  Polygon poly = clip_incident(ref, inc);
  // A cylinder's cap tilted against the reference: its true deepest rim point lies between two
  // polygon points (up to r (1 - cos(pi / 16)) deeper), so it is a candidate of its own.
  const Body& inc_body = ref_is_a ? b : a;
  if (inc_body.view->kind == ConvexKind::cylinder && inc.count >= 3 &&
      length_squared(cross(inc.normal, n)) >= flat_sin2) {
    Face deepest;
    const SupportPoint sp = support_at(inc_body, ref_is_a ? -n : n);
    deepest.count = 1;
    deepest.points[0] = sp.point;
    deepest.vertex[0] = deepest.edge[0] = deepest.feature = sp.feature;
    const Polygon extra = clip_incident(ref, deepest);
    for (unsigned i = 0; i < extra.n; ++i)
      poly.emit(extra.v[i]);
  }
  for (unsigned i = 0; i < poly.n; ++i) {
    const ClipVertex& v = poly.v[i];
    const Fixed t = dot(ref.normal, v.p) - plane;  // from a's core to b's along n
    const Vec3 on_a = ref_is_a ? v.p - n * t : v.p;
    const Vec3 on_b = ref_is_a ? v.p : v.p + n * t;
    const std::uint32_t id =
        ref_is_a ? pair_feature(v.on_ref, v.on_inc) : pair_feature(v.on_inc, v.on_ref);
    out.add(candidate(a, b, on_a, on_b, n, id), margin);
  }
  return n;
}

Segment as_segment(const Face& f) noexcept {
  const Vec3 p0 = f.points[0];
  const Vec3 p1 = f.points[f.count - 1];
  const Vec3 d = p1 - p0;
  return {p0 + half(d), normalize_or(d, Vec3::unit_x()), length(d) >> 1};
}

std::uint16_t segment_feature(const Face& f, Fixed s, Fixed half_length) noexcept {
  if (f.count < 2) return f.feature;
  if (s <= -half_length) return f.vertex[0];
  if (s >= half_length) return f.vertex[1];
  return f.feature;
}

/// Segments or points: the ends of the overlap of nearly parallel segments, else closest points.
Vec3 segment_contacts(const Body& a, const Body& b, const Face& fa, const Face& fb, Vec3 n,
                      bool apart, Fixed margin, Candidates& out) noexcept {
  const Segment sa = as_segment(fa);
  const Segment sb = as_segment(fb);
  OverlapEnd lo;
  OverlapEnd hi;
  if (fa.count == 2 && fb.count == 2 &&
      length_squared(cross(sa.direction, sb.direction)) < flat_sin2 &&
      segment_overlap(sa, sb, lo, hi)) {
    for (const bool top : {false, true}) {
      const OverlapEnd& end = top ? hi : lo;
      const Vec3 pa_end = sa.at(end.s);
      const Fixed t = clamp(dot(pa_end - sb.center, sb.direction), -sb.half_length, sb.half_length);
      const std::uint16_t on_a = end.a_end ? fa.vertex[top ? 1 : 0] : fa.feature;
      const std::uint16_t on_b = end.b_end ? fb.vertex[end.b_top ? 1 : 0] : fb.feature;
      out.add(candidate(a, b, pa_end, sb.at(t), n, pair_feature(on_a, on_b)), margin);
    }
    if (out.n > 0) return n;
  }
  const SegmentParams p = closest_on_segments(sa, sb);
  const Vec3 on_a = sa.at(p.s);
  const Vec3 on_b = sb.at(p.t);
  // Apart (only: overlapping segments' closest points say nothing of the shapes' overlap), the
  // closest points of the two features give the normal exactly (line against line, an
  // end against a line), better than a GJK direction iterated on a cylinder's curved side.
  // Only two lines crossing between their ends fix it whatever their positions (their common
  // perpendicular); an end or a point (a cylinder's rim) would carry the error of the direction
  // that chose it.
  const Vec3 v = on_b - on_a;
  const bool inside = abs(p.s) < sa.half_length && abs(p.t) < sb.half_length;
  if (apart && fa.count == 2 && fb.count == 2 && inside && dot(v, n) > Fixed::zero() &&
      length(v) > core_epsilon)
    n = normalize(v);
  out.add(candidate(a, b, on_a, on_b, n,
                    pair_feature(segment_feature(fa, p.s, sa.half_length),
                                 segment_feature(fb, p.t, sb.half_length))),
          margin);
  return n;
}

/// The feature of b's face that is nearest along `direction` when the face is not flat against
/// the other shape: a polytope face's supporting edge, a cylinder cap's exact rim point (its
/// polygon's chords lie inside the true rim).
Face supporting_feature(const Body& b, const Face& f, Vec3 direction) noexcept;

/// A polygon's edge farthest along `direction` (its lower end's height, ties to the first edge in
/// the face's own order), as a two-point face; segments and points are returned unchanged.
Face supporting_edge(const Face& f, Vec3 direction) noexcept {
  if (f.count < 3) return f;
  unsigned best = 0;
  Fixed best_height = Fixed::min();
  for (unsigned i = 0; i < f.count; ++i) {
    const unsigned j = (i + 1) % f.count;
    const Fixed h = min(dot(f.points[i], direction), dot(f.points[j], direction));
    if (h > best_height) {
      best_height = h;
      best = i;
    }
  }
  const unsigned j = (best + 1) % f.count;
  Face e;
  e.count = 2;
  e.points[0] = f.points[best];
  e.points[1] = f.points[j];
  e.vertex[0] = f.vertex[best];
  e.vertex[1] = f.vertex[j];
  e.edge[0] = e.edge[1] = f.edge[best];
  e.feature = f.edge[best];
  return e;
}

Face supporting_feature(const Body& b, const Face& f, Vec3 direction) noexcept {
  if (b.view->kind != ConvexKind::cylinder || f.count < 3) return supporting_edge(f, direction);
  const SupportPoint s = support_at(b, direction);
  Face point;
  point.count = 1;
  point.points[0] = s.point;
  point.vertex[0] = point.edge[0] = point.feature = s.feature;
  return point;
}

/// Chooses candidates one at a time, never one twice: the best unused one by a score (> 0 unless
/// `any`), ties to the lower feature ID, so the choice depends on the features, not on the order.
struct Picker {
  std::span<const Candidate> c;
  std::array<std::size_t, 4> chosen{};
  std::size_t count = 0;

  [[nodiscard]] bool used(std::size_t i) const noexcept {
    for (std::size_t k = 0; k < count; ++k)
      if (chosen[k] == i) return true;
    return false;
  }
  [[nodiscard]] Vec3 point(std::size_t k) const noexcept { return c[chosen[k]].point; }
  template <typename Score>
  bool pick(Score&& score, bool any) noexcept {
    std::size_t best = c.size();
    Fixed best_score;
    for (std::size_t i = 0; i < c.size(); ++i) {
      const Fixed s = score(c[i]);
      if (used(i) || (!any && s <= Fixed::zero())) continue;
      if (best == c.size() || beats(s, c[i].feature, best_score, c[best].feature)) {
        best = i;
        best_score = s;
      }
    }
    if (best < c.size()) chosen[count++] = best;
    return best < c.size();
  }
  bool pick_deepest() noexcept {
    return pick([](const Candidate& x) { return -x.separation; }, true);
  }
};

/// The first point: the deepest, where depths within 2^-16 m count as equal (lowest feature
/// wins), so that a face resting a hair off level (a cylinder's 16 rim points, a hull's hexagon)
/// keeps the same four points from step to step; the manifold's least separation may then exceed
/// the true least by at most 2^-16 m.
void pick_deepest_level(Picker& p) noexcept {
  Fixed lowest = Fixed::max();
  for (const Candidate& x : p.c)
    lowest = min(lowest, x.separation);
  p.pick(
      [&](const Candidate& x) {
        return x.separation <= lowest + core_epsilon ? Fixed::one() : Fixed::zero();
      },
      false);
}

/// Then the point farthest from the first, and the two that add the most area on either side of
/// that diagonal; with all on one side, the one that grows the triangle the most; collinear, the
/// deepest two others.
void pick_spread(Picker& p, Vec3 normal) noexcept {
  const Vec3 p0 = p.point(0);
  if (!p.pick([&](const Candidate& x) { return length_squared(x.point - p0); }, false)) return;
  const Vec3 p1 = p.point(1);
  const bool left =
      p.pick([&](const Candidate& x) { return area(p0, p1, x.point, normal); }, false);
  const bool right =
      p.pick([&](const Candidate& x) { return -area(p0, p1, x.point, normal); }, false);
  if (left == right) {
    if (!left) {
      p.pick_deepest();
      p.pick_deepest();
    }
    return;
  }
  const Vec3 p2 = p.point(2);
  const Vec3 up = left ? normal : -normal;
  const auto growth = [&](const Candidate& x) {
    return max(-area(p1, p2, x.point, up), -area(p2, p0, x.point, up));
  };
  if (!p.pick(growth, false)) p.pick_deepest();
}

}  // namespace manifold_detail

using namespace manifold_detail;

void reduce_into(std::span<const Candidate> c, Vec3 normal, Vec3 origin, Manifold& m) noexcept {
  const auto put = [&](const Candidate& x) {
    narrow::add_point(m, origin + x.point, x.separation, x.feature, Fixed::max());
  };
  if (c.size() <= 4) {
    for (const Candidate& x : c)
      put(x);
    return;
  }
  Picker picker{c};
  pick_deepest_level(picker);
  pick_spread(picker, normal);
  for (std::size_t k = 0; k < picker.count; ++k)
    put(c[picker.chosen[k]]);
}

Manifold manifold_from_faces(const Body& a, const Body& b, Vec3 n, Reference ref, Fixed margin,
                             bool apart) noexcept {
  const Face fa = face_at(a, n);
  const Face fb = face_at(b, -n);
  Candidates found;
  const bool poly_a = fa.count >= 3;
  const bool poly_b = fb.count >= 3;
  if (poly_a || poly_b) {
    bool ref_is_a = poly_a;
    if (poly_a && poly_b) {
      if (ref == Reference::b) {
        ref_is_a = false;
      } else if (ref == Reference::any) {
        const Fixed tolerance = Fixed::from_raw(Fixed::one_raw >> 16);
        ref_is_a = dot(-fb.normal, n) <= dot(fa.normal, n) + tolerance;
      }
    }
    const Vec3 toward = ref_is_a ? fa.normal : -fb.normal;
    if (dot(toward, n) >= face_cos) {
      n = clip_contacts(a, b, fa, fb, ref_is_a, margin, found);
    } else if (apart) {
      // Not a face contact (an edge or a vertex of a polytope is nearest): the supporting edges,
      // whose closest points are the contact, or two points when they lie along each other.
      n = segment_contacts(a, b, supporting_feature(a, fa, n), supporting_feature(b, fb, -n), n,
                           apart, margin, found);
    } else {
      // Overlapping off a face: the closest points of an edge and a rim say nothing of the
      // overlap; the deepest points along n do (their gap is the axis' own).
      const SupportPoint sa = support_at(a, n);
      const SupportPoint sb = support_at(b, -n);
      found.add(candidate(a, b, sa.point, sb.point, n, pair_feature(sa.feature, sb.feature)),
                margin);
    }
  } else {
    n = segment_contacts(a, b, fa, fb, n, apart, margin, found);
  }
  Manifold m;
  m.normal = n;
  reduce_into(std::span<const Candidate>(found.c.data(), found.n), n, a.origin, m);
  return m;
}

std::size_t clip_to_face(const Face& ref, const Face& inc, std::span<ClippedPoint> out) noexcept {
  const Polygon poly = clip_incident(ref, inc);
  std::size_t n = 0;
  for (unsigned i = 0; i < poly.n && n < out.size(); ++i)
    out[n++] = {poly.v[i].p, poly.v[i].on_ref, poly.v[i].on_inc};
  return n;
}

Manifold single_point(const Body& a, const Body& b, Vec3 on_a, Vec3 on_b, Vec3 n,
                      std::uint32_t feature, Fixed margin) noexcept {
  const Candidate c = candidate(a, b, on_a, on_b, n, feature);
  Manifold m;
  m.normal = n;
  narrow::add_point(m, a.origin + c.point, c.separation, c.feature, margin);
  return m;
}

}  // namespace detsim::sim_detail::convex

// collide_triangle: a convex shape against one triangle of a static surface (a mesh's or a
// heightfield's), one-sided, with internal-edge handling (convex.hpp states the rules).
//
// Everything is solved in a's frame (a unrotated at the origin), as collide_convex does, so world
// coordinates up to 2^30 m cost no precision: the triangle enters through one relative rotation.
//
// Round cores (sphere, capsule): the closest points of the core (a point, a segment) and the
// triangle (Ericson, Real-Time Collision Detection 5.1.5 and 5.1.9: an end against the triangle,
// the core against each edge, or the core crossing the triangle), less the radius.
// Polytopes and cylinders: the separating axis test over the triangle's normal, a's face normals
// and the edge pairs whose Gauss-map arcs meet (Gregorius, GDC 2013). A flat triangle's edge has
// a half circle for its arc (from n through the edge's outward direction to -n), so the pair test
// here is its own: a's arc must cross the plane perpendicular to the triangle's edge on the side
// opposite the edge's outward direction. Every axis is measured with the true supports (a
// cylinder's prism axes too), so any axis beyond the margin proves there is no contact; only
// axes that point into the triangle's back side (dot(l, -n) >= 2^-16) can become the normal.
// Then the reference face (the triangle's or a's) clips the other (convex_manifold.cpp), or the
// closest points of two edges, reduced to four points.
//
// Internal edges (Jolt's "active edges", Bullet's btAdjustInternalEdgeContacts): a normal that is
// not the face normal stays only when a candidate touches a real feature of the triangle (a convex
// or boundary edge, or a vertex beside one); otherwise the face normal, each candidate's pair of
// surface points projected on it before the reduction to four. The pair, not the separation, is
// projected: an edge pair's separation is its axis' gap, shorter than its clamped pair.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/vec3.hpp>

#include "../collide_util.hpp"
#include "convex_internal.hpp"
#include "triangle.hpp"

namespace detsim::sim_detail {

namespace convex::triangle_detail {

using namespace narrow;

/// The least dot(normal, -face normal) of a contact normal (one-sided rule): 2^-16.
constexpr Fixed kBackCos = Fixed::from_raw(Fixed::one_raw >> 16);

constexpr std::uint16_t tri_face = feature(Kind::face, 0);
constexpr std::uint16_t tri_edge(unsigned k) noexcept {
  return feature(Kind::edge, k);
}
constexpr std::uint16_t tri_vertex(unsigned k) noexcept {
  return feature(Kind::vertex, k);
}

/// The triangle in a's frame.
struct Tri {
  std::array<Vec3, 3> v;
  Vec3 n;                    ///< unit, the front side
  std::array<Vec3, 3> dir;   ///< unit, v[k] -> v[k + 1]
  std::array<Fixed, 3> len;  ///< |v[k + 1] - v[k]|
  std::array<Vec3, 3> out;   ///< the edge's outward direction in the plane: dir x n
  const TriangleData* data = nullptr;
};

Tri make_tri(const TriangleData& tri, const Mat3& rotation, Vec3 offset) noexcept {
  Tri t;
  t.data = &tri;
  for (unsigned k = 0; k < 3; ++k)
    t.v[k] = offset + rotation * tri.vertices[k];
  t.n = unit_or(rotation * tri.normal, Vec3::unit_y());
  for (unsigned k = 0; k < 3; ++k) {
    const Vec3 d = t.v[(k + 1) % 3] - t.v[k];
    t.len[k] = length(d);
    t.dir[k] = normalize_or(d, Vec3::unit_x());
    t.out[k] = normalize_or(cross(t.dir[k], t.n), Vec3::unit_x());
  }
  return t;
}

Face face_of(const Tri& t) noexcept {
  Face f;
  f.count = 3;
  for (unsigned k = 0; k < 3; ++k) {
    f.points[k] = t.v[k];
    f.vertex[k] = tri_vertex(k);
    f.edge[k] = tri_edge(k);
  }
  f.normal = t.n;
  f.feature = tri_face;
  return f;
}

/// Whether a triangle feature keeps a tilted normal: a convex or boundary edge, or a vertex with
/// one such edge beside it. The face and internal (flat, concave) edges do not.
bool real_feature(const Tri& t, std::uint16_t f) noexcept {
  const unsigned k = index_of(f) % 3;
  const auto& e = t.data->edges;
  if (kind_of(f) == Kind::edge) return !e[k].uses_face_normal();
  if (kind_of(f) == Kind::vertex)
    return !(e[k].uses_face_normal() && e[(k + 2) % 3].uses_face_normal());
  return false;
}

struct TriPoint {
  Vec3 q;
  std::uint16_t feature = tri_face;
};

bool inside_prism(const Tri& t, Vec3 p) noexcept {
  for (unsigned k = 0; k < 3; ++k)
    if (dot(p - t.v[k], t.out[k]) > Fixed::zero()) return false;
  return true;
}

/// The triangle's point closest to p: the projection when it falls inside, else the nearest
/// point of the three edges (ties to the lower edge), named face, edge or vertex.
TriPoint closest_on_triangle(const Tri& t, Vec3 p) noexcept {
  if (inside_prism(t, p)) return {p - t.n * dot(t.n, p - t.v[0]), tri_face};
  TriPoint best;
  Fixed best_d = Fixed::max();
  for (unsigned k = 0; k < 3; ++k) {
    const Fixed s = clamp(dot(p - t.v[k], t.dir[k]), Fixed::zero(), t.len[k]);
    TriPoint x{t.v[k] + t.dir[k] * s, tri_edge(k)};
    if (s == Fixed::zero()) x = {t.v[k], tri_vertex(k)};
    if (s == t.len[k]) x = {t.v[(k + 1) % 3], tri_vertex((k + 1) % 3)};
    const Fixed d = length(p - x.q);  // no overflow, whatever the distance
    if (d < best_d) {
      best_d = d;
      best = x;
    }
  }
  return best;
}

constexpr std::size_t kTriCandidates = 2 * max_face_points + 2;

/// Candidates with their pairs of surface points (a's, the triangle's), so that the internal-edge
/// rule can project each pair on the face normal.
struct TriCandidates {
  std::array<Candidate, kTriCandidates> c{};
  std::array<Vec3, kTriCandidates> pair{};  ///< the triangle's point minus a's
  std::size_t n = 0;
  void add(Vec3 on_a, Vec3 on_b, Fixed separation, std::uint32_t feature, Fixed margin) noexcept {
    if (separation > margin || n >= c.size()) return;
    c[n] = {midpoint(on_a, on_b), separation, feature};
    pair[n++] = on_b - on_a;
  }
};

/// The triangle as the reference face: a's supporting face toward it clipped by the triangle's
/// side planes, each point's height above the plane (less a's radius) its separation.
void face_contacts(const Body& a, const Tri& t, Fixed margin, TriCandidates& out) noexcept {
  const Face inc = face_at(a, -t.n);
  const Face ref = face_of(t);
  std::array<ClippedPoint, kTriCandidates> clipped{};
  std::size_t count = clip_to_face(ref, inc, clipped);
  // A cylinder's cap tilted against the triangle: its true lowest rim point is a point of its own.
  if (a.view->kind == ConvexKind::cylinder && inc.count >= 3 &&
      length_squared(cross(inc.normal, t.n)) >= flat_sin2) {
    const SupportPoint s = support_at(a, -t.n);
    Face point;
    point.count = 1;
    point.points[0] = s.point;
    point.vertex[0] = point.edge[0] = point.feature = s.feature;
    count += clip_to_face(ref, point, std::span(clipped).subspan(count));
  }
  for (std::size_t i = 0; i < count; ++i) {
    const Vec3 p = clipped[i].point;
    const Fixed h = dot(t.n, p - t.v[0]);
    const Vec3 on_a = p - t.n * a.radius;
    const Vec3 on_b = p - t.n * h;
    out.add(on_a, on_b, h - a.radius, pair_feature(clipped[i].on_inc, clipped[i].on_ref), margin);
  }
}

/// a's face (normal m) as the reference: the triangle clipped by its side planes. False when a
/// has no polygon facing m (a cylinder's prism side).
bool a_face_contacts(const Body& a, const Tri& t, Vec3 m, Fixed margin,
                     TriCandidates& out) noexcept {
  const Face ref = face_at(a, m);
  if (ref.count < 3 || dot(ref.normal, m) < face_cos) return false;
  const Fixed plane = dot(ref.normal, ref.points[0]);
  std::array<ClippedPoint, kTriCandidates> clipped{};
  const std::size_t count = clip_to_face(ref, face_of(t), clipped);
  for (std::size_t i = 0; i < count; ++i) {
    const Vec3 p = clipped[i].point;
    const Fixed s = dot(ref.normal, p) - plane;
    const Vec3 on_a = p - ref.normal * s;
    out.add(on_a, p, s, pair_feature(clipped[i].on_ref, clipped[i].on_inc), margin);
  }
  return true;
}

/// The last resort along l: a's support point against the triangle's (its plane's projection
/// for the face axis, else its deepest vertex, ties to the lower index).
void support_contact(const Body& a, const Tri& t, Vec3 l, bool face, Fixed margin,
                     TriCandidates& out) noexcept {
  const SupportPoint s = support_at(a, l);
  const Vec3 on_a = s.point + l * a.radius;
  if (face) {
    const Fixed h = dot(t.n, s.point - t.v[0]);
    out.add(on_a, s.point - t.n * h, h - a.radius, pair_feature(s.feature, tri_face), margin);
    return;
  }
  unsigned k = 0;
  for (unsigned i = 1; i < 3; ++i)
    if (dot(l, t.v[i]) < dot(l, t.v[k])) k = i;
  out.add(on_a, t.v[k], dot(l, t.v[k] - s.point) - a.radius, pair_feature(s.feature, tri_vertex(k)),
          margin);
}

// ---- Separating axes (polytopes and cylinders)
// ---------------------------------------------------

enum class AxisKind : std::uint8_t { triangle_face, a_face, edge };

struct Axis {
  Vec3 l;  ///< a -> triangle, unit
  Fixed separation = Fixed::min();
  AxisKind kind = AxisKind::triangle_face;
  bool found = false;
  unsigned index_a = 0;
  unsigned edge = 0;  ///< the triangle's edge
  void offer(Vec3 n, Fixed s, AxisKind k, unsigned ia, unsigned e) noexcept {
    if (found && s <= separation) return;
    *this = {n, s, k, true, ia, e};
  }
};

/// The gap of the projections on l (a -> triangle), less a's radius: a lower bound of the
/// distance.
Fixed gap(const Body& a, const Tri& t, Vec3 l) noexcept {
  const Fixed lowest = min(dot(l, t.v[0]), min(dot(l, t.v[1]), dot(l, t.v[2])));
  return lowest - dot(l, support_at(a, l).point) - a.radius;
}

bool into_back(const Tri& t, Vec3 l) noexcept {
  return dot(l, -t.n) >= kBackCos;
}

struct Sat {
  Axis face;    ///< the triangle's normal
  Axis a_face;  ///< a's best face that may be a normal
  Axis edge;    ///< the best edge pair that may be a normal
  bool beyond = false;
};

/// Whether a's edge (Gauss-map arc n0 -> n1) and the triangle's edge k make a face of the
/// Minkowski difference, and its normal x (a -> triangle, not unit): a's arc crosses the great
/// circle perpendicular to the edge, on the half opposite the edge's outward direction (the
/// negated half-circle arc of a flat polygon's edge).
bool edge_pair_normal(const SatEdge& e, const Tri& t, unsigned k, Vec3& x) noexcept {
  const Vec3 d = t.dir[k];
  const Fixed d0 = dot(e.n0, d);
  const Fixed d1 = dot(e.n1, d);
  if (d0 == d1) return false;  // the arc lies in the circle: the edges are parallel
  if ((d0 > Fixed::zero() && d1 > Fixed::zero()) || (d0 < Fixed::zero() && d1 < Fixed::zero()))
    return false;
  x = e.n1 * d0 - e.n0 * d1;  // the arc's point perpendicular to d, up to a positive factor...
  if (d0 < d1) x = -x;        // ...once oriented
  return dot(x, t.out[k]) <= Fixed::zero();
}

Sat separating_axes(const Body& a, const Tri& t, Fixed margin) noexcept {
  Sat s;
  const auto measure = [&](Vec3 l) {
    const Fixed g = gap(a, t, l);
    if (g > margin) s.beyond = true;
    return g;
  };
  s.face.offer(-t.n, measure(-t.n), AxisKind::triangle_face, 0, 0);
  const ConvexView& v = *a.view;
  for (unsigned i = 0; i < sat_face_count(v) && !s.beyond; ++i) {
    const SatFace f = sat_face(v, i);  // a is unrotated: local is the pair's frame
    const Fixed g = measure(f.normal);
    if (f.exact && into_back(t, f.normal)) s.a_face.offer(f.normal, g, AxisKind::a_face, i, 0);
  }
  for (unsigned i = 0; i < sat_edge_count(v) && !s.beyond; ++i) {
    const SatEdge e = sat_edge(v, i);
    if (e.circle) continue;
    for (unsigned k = 0; k < 3 && !s.beyond; ++k) {
      const Vec3 w = cross(e.direction, t.dir[k]);
      Vec3 x;
      if (length_squared(w) < parallel_sin2 || !edge_pair_normal(e, t, k, x)) continue;
      Vec3 l = normalize(w);
      if (dot(l, x) < Fixed::zero()) l = -l;
      const Fixed g = measure(l);
      if (e.exact && into_back(t, l)) s.edge.offer(l, g, AxisKind::edge, i, k);
    }
  }
  return s;
}

/// The closest points of a's edge and the triangle's edge of an edge axis: one point.
void edge_contact(const Body& a, const Tri& t, const Axis& axis, Fixed margin,
                  TriCandidates& out) noexcept {
  const SatEdge e = sat_edge(*a.view, axis.index_a);
  const Vec3 p0 = a.position + e.p0;
  const Vec3 p1 = a.position + e.p1;
  const unsigned k = axis.edge;
  const Segment sa{midpoint(p0, p1), e.direction, length(p1 - p0) >> 1};
  const Segment sb{midpoint(t.v[k], t.v[(k + 1) % 3]), t.dir[k], t.len[k] >> 1};
  const SegmentParams p = closest_on_segments(sa, sb);
  std::uint16_t on_tri = tri_edge(k);
  if (p.t <= -sb.half_length) on_tri = tri_vertex(k);
  if (p.t >= sb.half_length) on_tri = tri_vertex((k + 1) % 3);
  const Vec3 on_a = sa.at(p.s) + axis.l * a.radius;
  out.add(on_a, sb.at(p.t), axis.separation, pair_feature(e.feature, on_tri), margin);
}

/// The polytope / cylinder manifold: SAT, the chosen axis' contacts (the triangle's face unless
/// a's face or an edge pair is clearly better, collide_util's bias), else the support points.
Vec3 polytope_contacts(const Body& a, const Tri& t, Fixed margin, TriCandidates& out) noexcept {
  const Sat s = separating_axes(a, t, margin);
  if (s.beyond) return {};
  const Fixed scale = Fixed::one() + bounding_radius(*a.view);
  Axis axis = s.face;
  if (s.a_face.found && clearly_greater(s.a_face.separation, axis.separation, scale))
    axis = s.a_face;
  if (s.edge.found && clearly_greater(s.edge.separation, axis.separation, scale)) axis = s.edge;
  bool made = true;
  switch (axis.kind) {
    case AxisKind::triangle_face:
      face_contacts(a, t, margin, out);
      made = out.n > 0;
      break;
    case AxisKind::a_face:
      made = a_face_contacts(a, t, axis.l, margin, out) && out.n > 0;
      break;
    case AxisKind::edge:
      edge_contact(a, t, axis, margin, out);
      made = out.n > 0;
      break;
  }
  if (!made && axis.separation <= margin)
    support_contact(a, t, axis.l, axis.kind == AxisKind::triangle_face, margin, out);
  return axis.l;
}

// ---- Round cores (sphere, capsule)
// ---------------------------------------------------------------

struct CorePair {
  Vec3 on_a;  ///< a core point
  Vec3 on_b;  ///< a triangle point
  Fixed distance = Fixed::max();
  std::uint32_t feature = 0;
  bool meet = false;  ///< the core crosses the triangle
};

CorePair closest_core(const Body& a, const Tri& t) noexcept {
  const bool capsule = a.view->kind == ConvexKind::capsule;
  const Fixed h = capsule ? a.view->half_height : Fixed::zero();
  const Vec3 e0 = a.position + Vec3{Fixed::zero(), -h, Fixed::zero()};
  const Vec3 e1 = a.position + Vec3{Fixed::zero(), h, Fixed::zero()};
  CorePair best;
  const auto offer = [&](Vec3 p, Vec3 q, std::uint16_t fa, std::uint16_t fb) {
    const Fixed d = length(q - p);
    if (d < best.distance) best = {p, q, d, pair_feature(fa, fb), false};
  };
  const TriPoint q0 = closest_on_triangle(t, e0);
  offer(e0, q0.q, capsule ? capsule_end(false) : whole_shape, q0.feature);
  if (!capsule || h == Fixed::zero()) return best;
  const TriPoint q1 = closest_on_triangle(t, e1);
  offer(e1, q1.q, capsule_end(true), q1.feature);
  const Segment core{a.position, Vec3::unit_y(), h};
  for (unsigned k = 0; k < 3; ++k) {
    const Segment edge{midpoint(t.v[k], t.v[(k + 1) % 3]), t.dir[k], t.len[k] >> 1};
    const SegmentParams p = closest_on_segments(core, edge);
    std::uint16_t on_tri = tri_edge(k);
    if (p.t <= -edge.half_length) on_tri = tri_vertex(k);
    if (p.t >= edge.half_length) on_tri = tri_vertex((k + 1) % 3);
    offer(core.at(p.s), edge.at(p.t), capsule_feature_at(p.s, h), on_tri);
  }
  // The core through the triangle: its ends on either side of the plane, the crossing inside.
  const Fixed z0 = dot(t.n, e0 - t.v[0]);
  const Fixed z1 = dot(t.n, e1 - t.v[0]);
  const bool crosses = (z0 <= Fixed::zero()) != (z1 <= Fixed::zero());
  if (crosses && inside_prism(t, e0 + (e1 - e0) * (z0 / (z0 - z1)))) best.meet = true;
  return best;
}

Vec3 round_contacts(const Body& a, const Tri& t, Fixed margin, TriCandidates& out) noexcept {
  const CorePair c = closest_core(a, t);
  if (!c.meet && c.distance - a.radius > margin) return {};
  if (c.meet || c.distance <= core_epsilon) {
    face_contacts(a, t, margin, out);
    if (out.n == 0) support_contact(a, t, -t.n, true, margin, out);
    return -t.n;
  }
  const Vec3 n = normalize(c.on_b - c.on_a);
  if (dot(n, -t.n) >= face_cos) {  // over the face: the face's points (two for a lying capsule)
    face_contacts(a, t, margin, out);
    if (out.n > 0) return -t.n;
  }
  out.add(c.on_a + n * a.radius, c.on_b, c.distance - a.radius, c.feature, margin);
  return n;
}

/// The internal-edge rule: a normal other than the face's stays only when a candidate touches a
/// real feature; else the face normal, each candidate's pair of surface points projected on it
/// (its midpoint unchanged), those beyond the margin dropped.
Vec3 remove_internal_edges(const Tri& t, Vec3 normal, Fixed margin, TriCandidates& found) noexcept {
  const Vec3 face = -t.n;
  if (normal == face) return normal;
  for (std::size_t i = 0; i < found.n; ++i)
    if (real_feature(t, static_cast<std::uint16_t>(found.c[i].feature >> 16))) return normal;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < found.n; ++i) {
    const Fixed separation = dot(found.pair[i], face);
    if (separation > margin) continue;
    found.c[kept] = {found.c[i].point, separation, found.c[i].feature};
    found.pair[kept++] = found.pair[i];
  }
  found.n = kept;
  return face;
}

}  // namespace convex::triangle_detail

Manifold collide_triangle(const ConvexView& a, const Pose& pa, const TriangleData& tri,
                          const Pose& surface, Fixed margin) noexcept {
  using namespace convex;
  using namespace convex::triangle_detail;
  // Far apart in the world (beyond any size of geometry): nothing, before a difference of two
  // positions up to 2^30 m could leave the Fixed range.
  const Vec3 apart = narrow::half(surface.position) - narrow::half(pa.position);
  const Fixed far = Fixed::from_int(1 << 28);
  if (abs(apart.x) > far || abs(apart.y) > far || abs(apart.z) > far) return {};
  const Mat3 to_a = transpose(pa.rotation);
  const Tri t = make_tri(tri, to_a * surface.rotation, to_a * (surface.position - pa.position));
  const Body A = make_body(a, Pose{Vec3{}, Mat3::identity()}, Vec3{});
  // a's bounding sphere beyond the margin from the triangle's bounds, then from the triangle.
  const Fixed reach = bounding_radius(a) + margin;
  for (int i = 0; i < 3; ++i) {
    const auto c = [&](unsigned k) { return narrow::component(t.v[k], i); };
    if (min(c(0), min(c(1), c(2))) > reach || max(c(0), max(c(1), c(2))) < -reach) return {};
  }
  if (length(closest_on_triangle(t, Vec3{}).q) - bounding_radius(a) > margin) return {};
  // One-sided: a's centre (a hull's bounding-box centre) behind the plane by more than the margin.
  const Vec3 centre =
      a.kind == ConvexKind::hull ? narrow::half(a.hull->aabb_min + a.hull->aabb_max) : Vec3{};
  if (dot(t.n, centre - t.v[0]) < -margin) return {};
  TriCandidates found;
  const bool round = a.kind == ConvexKind::sphere || a.kind == ConvexKind::capsule;
  Vec3 normal =
      round ? round_contacts(A, t, margin, found) : polytope_contacts(A, t, margin, found);
  normal = remove_internal_edges(t, normal, margin, found);
  if (found.n == 0 || !into_back(t, normal)) return {};
  Manifold m;
  m.normal = normal;
  reduce_into(std::span<const convex::Candidate>(found.c.data(), found.n), normal, Vec3{}, m);
  return narrow::to_world(m, pa);
}

}  // namespace detsim::sim_detail

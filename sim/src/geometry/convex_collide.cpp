// collide_convex: the separating axis test over face normals and Gauss-map-pruned edge pairs
// (Gregorius, "The Separating Axis Test between Convex Polyhedra", GDC 2013), with every axis
// measured by the true support functions of the cores; GJK closest points for cores that are
// apart; then the supporting faces' clipped manifold (convex_manifold.cpp).
//
// Why supports rather than face offsets and edge points: a cylinder's axes come from its 16-gon
// prism, but its extent along any axis is the true cylinder's, so every separation below is a
// true lower bound of the distance (an axis beyond the margin proves there is no contact) and the
// flat contacts (a cap, a box or hull face) are measured exactly.
//
// Order of decisions (each deterministic, ties to the lower index):
// 0. the pair is solved in a canonical order (order_key) and mirrored, so (b, a) mirrors (a, b);
// 1. bounding spheres beyond the margin: nothing;
// 2. a round core (sphere point, capsule segment) or a cylinder: GJK closest points of the cores;
//    apart when GJK's direction separates their projections: the supporting faces along it,
//    kept when they agree with GJK's distance, else the closest points (apart());
// 3. otherwise (and for cores that meet) SAT: a's faces, b's faces (a cylinder adds its radial
//    direction), edge pairs, each replacing the incumbent only when clearly greater
//    (collide_util's bias, the same rule as box_box); an overlap on a cylinder's inexact prism
//    axis is refined by a pattern search (refine_axis);
// 4. a face axis clips the incident face against the reference face; an edge axis between true
//    edges gives the closest points of the two edges (one point, as box_box); an overlap off
//    any face gives the deepest points along the axis;
// 5. apart, and the axis made no contact (corners passing each other): GJK closest points.
#include <array>
#include <cstdint>
#include <vector>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/vec3.hpp>

#include "../collide_util.hpp"
#include "convex_internal.hpp"

namespace detsim::sim_detail {

namespace convex::collide_detail {

using namespace narrow;

bool is_round(const ConvexView& v) noexcept {
  return v.kind == ConvexKind::sphere || v.kind == ConvexKind::capsule;
}

/// A point inside the core (for orienting edge axes): a hull's bounding-box centre, else the
/// origin.
Vec3 interior(const Body& b) noexcept {
  if (b.view->kind != ConvexKind::hull) return b.position;
  return b.position + b.rotation * half(b.view->hull->aabb_min + b.view->hull->aabb_max);
}

/// The gap between the cores' projections on l (a -> b), less the radii: a lower bound of the
/// distance between the shapes.
Fixed separation_along(const Body& a, const Body& b, Vec3 l) noexcept {
  return dot(l, support_at(b, -l).point - support_at(a, l).point) - a.radius - b.radius;
}

struct Best {
  Vec3 normal;  ///< a -> b
  Fixed separation = Fixed::min();
  bool found = false;
  bool exact = true;
  unsigned index_a = 0;
  unsigned index_b = 0;
  /// A candidate replaces the best when strictly greater: the first of equals (lowest index) wins.
  void offer(Vec3 n, Fixed s, bool is_exact, unsigned ia, unsigned ib) noexcept {
    if (found && s <= separation) return;
    *this = {n, s, true, is_exact, ia, ib};
  }
};

struct Sat {
  Best face_a;
  Best face_b;
  Best edge;
  bool beyond = false;  ///< an axis separates by more than the margin
};

struct WorldEdge {
  Vec3 p0;
  Vec3 local_p1;   ///< the other end, in the body's frame (only edge contacts need it posed)
  Vec3 direction;  ///< unit, p0 -> p1
  Vec3 n0;         ///< the Gauss-map arc (world)
  Vec3 n1;
  Vec3 arc;  ///< n1 x n0: perpendicular to the arc's plane
  std::uint16_t feature = 0;
  bool circle = false;
  bool exact = true;
};

/// Edge i of b posed in world space. A box's direction and arc are its rotation's columns.
WorldEdge world_edge(const Body& b, unsigned i) noexcept {
  const SatEdge e = sat_edge(*b.view, i);
  WorldEdge w;
  w.p0 = b.unrotated ? b.position + e.p0 : b.position + b.rotation * e.p0;
  w.local_p1 = e.p1;
  w.feature = e.feature;
  w.circle = e.circle;
  w.exact = e.exact;
  if (b.unrotated) {
    w.direction = e.direction;
    w.n0 = e.n0;
    w.n1 = e.n1;
  } else if (b.view->kind == ConvexKind::box) {
    const unsigned axis = i / 4;
    w.direction = b.rotation.column(axis);
    const Vec3 u = b.rotation.column((axis + 1) % 3);
    const Vec3 v = b.rotation.column((axis + 2) % 3);
    w.n0 = (i & 1U) != 0 ? u : -u;
    w.n1 = (i & 2U) != 0 ? v : -v;
  } else {
    w.direction = b.rotation * e.direction;
    w.n0 = b.rotation * e.n0;
    w.n1 = b.rotation * e.n1;
  }
  w.arc = cross(w.n1, w.n0);
  return w;
}

/// The edges of b in world space, posed once per pair when there are at most kCachedEdges of
/// them; larger hulls pose them as they are read. For a hull of at most kCachedFaces faces, also
/// its faces' world normals and each edge's two faces (`by_face`): an edge's Gauss-map arc ends
/// are its faces' normals, so the first Minkowski-face test of an edge of a against every edge of
/// b needs one sign per face of b, not two per edge (edge_axes).
constexpr unsigned kCachedEdges = 64;
constexpr unsigned kCachedFaces = 64;
// PosedEdges' lists, reused from pair to pair (one set per thread): filled, never zeroed.
struct PosedLists {
  std::vector<WorldEdge> edges;
  std::vector<Vec3> normals;
  std::vector<std::array<std::uint16_t, 2>> face_of;
};
PosedLists& posed_lists() {
  thread_local PosedLists lists;
  return lists;
}
struct PosedEdges {
  const Body& body;
  unsigned count;
  PosedLists& lists = posed_lists();
  bool by_face = false;
  unsigned faces = 0;
  explicit PosedEdges(const Body& b) noexcept : body(b), count(sat_edge_count(*b.view)) {
    if (count > kCachedEdges) return;
    lists.edges.clear();
    for (unsigned i = 0; i < count; ++i)
      lists.edges.push_back(world_edge(b, i));
    if (b.view->kind != ConvexKind::hull || b.view->hull->faces.size() > kCachedFaces) return;
    const Hull& h = *b.view->hull;
    by_face = true;
    faces = static_cast<unsigned>(h.faces.size());
    lists.normals.clear();
    for (unsigned f = 0; f < faces; ++f)  // as world_edge turns them: the same bits
      lists.normals.push_back(b.unrotated ? h.faces[f].normal : b.rotation * h.faces[f].normal);
    lists.face_of.clear();
    for (unsigned i = 0; i < count; ++i)
      lists.face_of.push_back({h.edges[i].face_0, h.edges[i].face_1});
  }
  PosedEdges(const PosedEdges&) = delete;
  PosedEdges& operator=(const PosedEdges&) = delete;
  /// Edge i, from the cache or posed into `scratch`.
  [[nodiscard]] const WorldEdge& at(unsigned i, WorldEdge& scratch) const noexcept {
    if (count <= kCachedEdges) return lists.edges[i];
    scratch = world_edge(body, i);
    return scratch;
  }
  [[nodiscard]] Vec3 normal(unsigned f) const noexcept { return lists.normals[f]; }
  [[nodiscard]] const std::array<std::uint16_t, 2>& faces_of(unsigned i) const noexcept {
    return lists.face_of[i];
  }
};

int sign(Fixed x) noexcept {
  return x > Fixed::zero() ? 1 : (x < Fixed::zero() ? -1 : 0);
}

/// The sign of u . v for vectors of length <= 1 (Gauss-map normals and their cross products),
/// from 16-bit-truncated components in 64-bit integers: exact integer arithmetic (deterministic),
/// about 2^-31 of resolution, and several times cheaper than the exact Fixed dot, which the
/// all-pairs edge test would otherwise call ~2 E_a E_b times.
int sign_of_dot(Vec3 u, Vec3 v) noexcept {
  constexpr std::int64_t unit = std::int64_t{1} << 16;
  const std::int64_t sum = (u.x.raw() / unit) * (v.x.raw() / unit) +
                           (u.y.raw() / unit) * (v.y.raw() / unit) +
                           (u.z.raw() / unit) * (v.z.raw() / unit);
  return sum > 0 ? 1 : (sum < 0 ? -1 : 0);
}

/// Whether the arc (n0, n1) crosses the great circle perpendicular to u.
bool arc_meets_circle(Vec3 n0, Vec3 n1, Vec3 u) noexcept {
  return sign_of_dot(n0, u) * sign_of_dot(n1, u) <= 0;
}

/// Whether edges ea (of a) and eb (of b) make a face of the Minkowski difference: their Gauss-map
/// arcs, a's and b's negated, intersect (Gregorius). A segment core's arc is a whole circle.
/// The second half of the arcs' test (minkowski_face), given the first's sign cba.
bool arcs_cross(const WorldEdge& ea, const WorldEdge& eb, int cba) noexcept {
  const int adc = sign_of_dot(ea.n0, eb.arc);
  const int bdc = sign_of_dot(ea.n1, eb.arc);
  return adc * bdc < 0 && cba * bdc > 0;
}

bool minkowski_face(const WorldEdge& ea, const WorldEdge& eb) noexcept {
  if (ea.circle && eb.circle) return true;
  if (ea.circle) return arc_meets_circle(-eb.n0, -eb.n1, ea.direction);
  if (eb.circle) return arc_meets_circle(ea.n0, ea.n1, eb.direction);
  // Arcs (a, b) = (ea.n0, ea.n1) and (c, d) = (-eb.n0, -eb.n1); b x a and d x c = (eb.n1 x eb.n0)
  // are each edge's `arc`, made once per edge. Most pairs fail the first test.
  const int cba = -sign_of_dot(eb.n0, ea.arc);
  const int dba = -sign_of_dot(eb.n1, ea.arc);
  if (cba * dba >= 0) return false;
  return arcs_cross(ea, eb, cba);
}

void face_axes(const Body& owner, const Body& a, const Body& b, bool owner_is_a, Fixed margin,
               Best& best, bool& beyond) noexcept {
  const unsigned count = sat_face_count(*owner.view);
  for (unsigned i = 0; i < count && !beyond; ++i) {
    const SatFace f = sat_face(*owner.view, i);
    const Vec3 m = owner.rotation * f.normal;  // unit to ~10 ulp: enough to measure a gap
    const Vec3 l = owner_is_a ? m : -m;
    const Fixed s = separation_along(a, b, l);
    if (s > margin) beyond = true;
    best.offer(l, s, f.exact, i, i);
  }
  // The winner becomes a contact normal: unit within 2 ulp (collide_util's unit_or).
  if (best.found) best.normal = unit_or(best.normal, Vec3::unit_y());
}

void edge_axes(const Body& a, const Body& b, Fixed margin, Best& best, bool& beyond) noexcept {
  const unsigned count_a = sat_edge_count(*a.view);
  const PosedEdges edges_b(b);
  const Vec3 inside_a = interior(a);
  const Vec3 inside_b = interior(b);
  const bool straight =
      a.view->kind != ConvexKind::cylinder && b.view->kind != ConvexKind::cylinder;
  WorldEdge scratch;
  std::array<int, kCachedFaces> side;  // -(b's face normal . ea's arc), by face of b (as filled)
  for (unsigned i = 0; i < count_a && !beyond; ++i) {
    const WorldEdge ea = world_edge(a, i);
    const bool by_face = edges_b.by_face && !ea.circle;
    for (unsigned f = 0; by_face && f < edges_b.faces; ++f)
      side[f] = -sign_of_dot(edges_b.normal(f), ea.arc);
    for (unsigned j = 0; j < edges_b.count && !beyond; ++j) {
      const WorldEdge& eb = edges_b.at(j, scratch);
      if (by_face) {
        // minkowski_face's first test from the faces' signs (the same bits), then its second.
        const int cba = side[edges_b.faces_of(j)[0]];
        if (cba * side[edges_b.faces_of(j)[1]] >= 0 || !arcs_cross(ea, eb, cba)) continue;
      } else if (!minkowski_face(ea, eb)) {
        continue;
      }
      const Vec3 w = cross(ea.direction, eb.direction);
      if (length_squared(w) < parallel_sin2) continue;  // parallel edges add no direction
      Vec3 l = normalize(w);
      const Fixed out = ea.circle ? dot(l, inside_b - eb.p0) : dot(l, ea.p0 - inside_a);
      if (out < Fixed::zero()) l = -l;
      // On a face of the Minkowski difference both edges support their shapes along l
      // (Gregorius), so the edges' own gap is the axis' gap, without a support search; a
      // cylinder's prism edges are not the cylinder's, so it is measured.
      const Fixed s =
          straight ? dot(l, eb.p0 - ea.p0) - a.radius - b.radius : separation_along(a, b, l);
      if (s > margin) beyond = true;
      best.offer(l, s, ea.exact && eb.exact, i, j);
    }
  }
}

/// A cylinder's side direction toward the other shape's interior: the normal of two cylinders
/// lying side by side (logs), or of a side against a shape beside it, which no prism face has.
/// Offered after the prism's faces, as a face of the cylinder.
void radial_axis(const Body& owner, const Body& other, bool owner_is_a, Fixed margin, Best& best,
                 bool& beyond) noexcept {
  if (owner.view->kind != ConvexKind::cylinder || beyond) return;
  const Vec3 axis = owner.rotation.column(1);
  const Vec3 d = interior(other) - owner.position;
  const Vec3 radial = d - axis * dot(d, axis);
  if (length_squared(radial) == Fixed::zero()) return;
  const Vec3 m = normalize(radial);
  const Vec3 l = owner_is_a ? m : -m;
  const Fixed s =
      owner_is_a ? separation_along(owner, other, l) : separation_along(other, owner, l);
  if (s > margin) beyond = true;
  best.offer(l, s, true, sat_face_count(*owner.view), 0);
}

Sat separating_axes(const Body& a, const Body& b, Fixed margin) noexcept {
  Sat s;
  face_axes(a, a, b, true, margin, s.face_a, s.beyond);
  radial_axis(a, b, true, margin, s.face_a, s.beyond);
  face_axes(b, a, b, false, margin, s.face_b, s.beyond);
  radial_axis(b, a, false, margin, s.face_b, s.beyond);
  edge_axes(a, b, margin, s.edge, s.beyond);
  return s;
}

/// A cylinder's penetration normal between the directions of its finite axis set: the gap
/// f(l) = l . (s_b(-l) - s_a(l)) is minus the depth along l, and is not smooth where a support
/// jumps across a rim, so a pattern search climbs it: from the axis, try l tilted by +-t about
/// two perpendicular directions, move to the best that raises f, else halve t (from 0.1 rad,
/// 16 rounds at most, ties to the first tried). Deterministic, and never worse than the axis.
Best refine_axis(const Body& a, const Body& b, Best axis) noexcept {
  Fixed step = Fixed::from_raw(Fixed::one_raw / 10);
  for (int round = 0; round < 16; ++round) {
    const Vec3 e1 = any_perpendicular(axis.normal);
    const Vec3 e2 = cross(axis.normal, e1);
    Best next = axis;
    const Vec3 d1 = (e1 + e2) * (Fixed::sqrt2() >> 1);
    const Vec3 d2 = (e1 - e2) * (Fixed::sqrt2() >> 1);
    for (const Vec3 e : {e1, -e1, e2, -e2, d1, -d1, d2, -d2}) {
      const Vec3 l = normalize(axis.normal + e * step);
      const Fixed f = separation_along(a, b, l);
      if (f > next.separation) {
        next.normal = l;
        next.separation = f;
      }
    }
    if (next.separation > axis.separation) {
      axis = next;
    } else {
      step = step >> 1;
    }
  }
  return axis;
}

/// How far above a lower bound of the distance a separation may be from rounding alone (2^-20 m).
constexpr Fixed rounding_slack = Fixed::from_raw(Fixed::one_raw >> 20);

Fixed deepest_separation(const Manifold& m) noexcept {
  Fixed deepest = Fixed::max();
  for (std::uint8_t i = 0; i < m.count; ++i)
    deepest = min(deepest, m.points[i].separation);
  return deepest;
}

/// Cores apart (GJK): separation = distance - radii, normal along the closest points.
Manifold apart(const Body& a, const Body& b, const Closest& c, Fixed margin) noexcept {
  if (c.distance - a.radius - b.radius > margin) return {};
  const Vec3 n = normalize(c.on_b - c.on_a);
  Manifold m = manifold_from_faces(a, b, n, Reference::any, margin, true);
  // The supporting features' own closest points corrected the normal (GJK converges slowly on a
  // cylinder's side): once more along it, so that the features themselves sit where it says.
  if (m.count > 0 && m.normal != n) {
    const Manifold again = manifold_from_faces(a, b, m.normal, Reference::any, margin, true);
    if (again.count > 0) m = again;
  }
  // Separations apart must be lower bounds of the distance (the time-of-impact sweep advances by
  // them): the gap of the projections on the normal is one. The faces' deepest point may not
  // exceed it (beyond 2^-20 m of rounding) and must be GJK's distance (within 2^-12 m); otherwise
  // they are not the nearest features (an edge beside the nearest point, a rim seen through its
  // polygon) and the closest points are the contact, at the bound along GJK's direction.
  const Fixed measured = c.distance - a.radius - b.radius;
  if (m.count > 0) {
    const Fixed deepest = deepest_separation(m);
    if (deepest <= separation_along(a, b, m.normal) + rounding_slack &&
        abs(deepest - measured) <= (core_epsilon << 4))
      return m;
  }
  const std::uint32_t id = pair_feature(face_at(a, n).feature, face_at(b, -n).feature);
  Manifold one = single_point(a, b, c.on_a, c.on_b, n, id, margin);
  if (one.count > 0)
    one.points[0].separation = min(one.points[0].separation, separation_along(a, b, n));
  return one;
}

/// The two support points along n as one contact: the last resort of overlapping cores.
Manifold support_pair(const Body& a, const Body& b, Vec3 n, Fixed margin) noexcept {
  const SupportPoint sa = support_at(a, n);
  const SupportPoint sb = support_at(b, -n);
  return single_point(a, b, sa.point, sb.point, n, pair_feature(sa.feature, sb.feature), margin);
}

/// Edge against edge between true straight edges: one point midway between their closest points
/// (box_box's rule), or nothing when the edges pass each other apart.
bool edge_point(const Body& a, const Body& b, const Best& e, Fixed margin, Manifold& m) noexcept {
  const WorldEdge ea = world_edge(a, e.index_a);
  const WorldEdge eb = world_edge(b, e.index_b);
  const Vec3 pa1 = a.position + a.rotation * ea.local_p1;
  const Vec3 pb1 = b.position + b.rotation * eb.local_p1;
  const Segment sa{midpoint(ea.p0, pa1), ea.direction, length(pa1 - ea.p0) >> 1};
  const Segment sb{midpoint(eb.p0, pb1), eb.direction, length(pb1 - eb.p0) >> 1};
  const SegmentParams p = closest_on_segments(sa, sb);
  const bool crossing = abs(p.s) < sa.half_length && abs(p.t) < sb.half_length;
  if (!crossing && e.separation > Fixed::zero()) return false;
  const Vec3 on_a = sa.at(p.s) + e.normal * a.radius;
  const Vec3 on_b = sb.at(p.t) - e.normal * b.radius;
  m = {};
  m.normal = e.normal;
  add_point(m, a.origin + midpoint(on_a, on_b), e.separation, pair_feature(ea.feature, eb.feature),
            margin);
  return true;
}

}  // namespace convex::collide_detail

namespace convex::collide_detail {

/// A total order on posed views, independent of the argument order: kind, dimensions, a hull's
/// vertex count, bounds and radius, then the pose's raw values. Never addresses (rule 4: not
/// machine-dependent). Equal keys (the same shape at the same pose) solve as given.
std::array<std::int64_t, 26> order_key(const ConvexView& v, const Pose& p) noexcept {
  const Hull empty;
  const Hull& h = v.hull != nullptr ? *v.hull : empty;
  const Mat3& r = p.rotation;
  return {static_cast<std::int64_t>(v.kind),
          v.radius.raw(),
          v.half_height.raw(),
          v.half_extents.x.raw(),
          v.half_extents.y.raw(),
          v.half_extents.z.raw(),
          static_cast<std::int64_t>(h.vertices.size()),
          h.bounding_radius.raw(),
          h.aabb_min.x.raw(),
          h.aabb_min.y.raw(),
          h.aabb_min.z.raw(),
          h.aabb_max.x.raw(),
          h.aabb_max.y.raw(),
          h.aabb_max.z.raw(),
          p.position.x.raw(),
          p.position.y.raw(),
          p.position.z.raw(),
          r.rows[0].x.raw(),
          r.rows[0].y.raw(),
          r.rows[0].z.raw(),
          r.rows[1].x.raw(),
          r.rows[1].y.raw(),
          r.rows[1].z.raw(),
          r.rows[2].x.raw(),
          r.rows[2].y.raw(),
          r.rows[2].z.raw()};
}

/// GJK's cores apart, and proven so: GJK's direction must separate the cores' projections (a
/// simplex flattened by rounding can stop short of an origin that lies inside).
bool proven_apart(const Body& a, const Body& b, const Closest& c) noexcept {
  return !c.overlap && c.distance > core_epsilon &&
         separation_along(a, b, normalize(c.on_b - c.on_a)) + a.radius + b.radius > Fixed::zero();
}

/// The axis that makes the contact: a's best face, b's if clearly better, an edge pair if clearly
/// better than either (collide_util's bias, as box_box).
struct Choice {
  Best axis;
  bool edge = false;
  Reference ref = Reference::any;
};
Choice choose_axis(const Sat& s, Fixed scale) noexcept {
  const bool ref_is_b =
      s.face_b.found &&
      (!s.face_a.found || clearly_greater(s.face_b.separation, s.face_a.separation, scale));
  const Best& face = ref_is_b ? s.face_b : s.face_a;
  const bool edge =
      s.edge.found && (!face.found || clearly_greater(s.edge.separation, face.separation, scale));
  if (edge) return {s.edge, true, Reference::any};
  return {face, false, ref_is_b ? Reference::b : Reference::a};
}

/// The contact the chosen axis makes: straight edges their closest points; otherwise the
/// supporting faces along it. Overlapping, always a contact (with a cylinder, the faces' points
/// must be as deep as the axis says, else the deepest points along it: side lines may cross
/// beside an overlapping rim). Apart, false when the axis does not give the nearest features: a
/// cylinder's (GJK measures it), or a face whose clipped points are deeper than its own gap (a
/// corner beside it).
bool axis_contact(const Body& a, const Body& b, const Choice& choice, bool curved, Fixed margin,
                  Manifold& m) noexcept {
  const Best& axis = choice.axis;
  const bool apart_on_axis = axis.separation > Fixed::zero();
  if (choice.edge && !curved && axis.exact) return edge_point(a, b, axis, margin, m);
  if (apart_on_axis && (curved || !axis.exact)) return false;
  m = manifold_from_faces(a, b, axis.normal, choice.ref, margin);
  if (apart_on_axis)
    return m.count > 0 && deepest_separation(m) <= axis.separation + rounding_slack;
  const bool deep_enough =
      !curved || deepest_separation(m) <= axis.separation + (core_epsilon << 4);
  if (m.count == 0 || !deep_enough) m = support_pair(a, b, axis.normal, margin);
  return true;
}

Manifold collide_ordered(const ConvexView& a, const Pose& pa, const ConvexView& b, const Pose& pb,
                         Fixed margin) noexcept;
Manifold collide_local(const Body& a, const Body& b, Fixed margin) noexcept;

}  // namespace convex::collide_detail

Manifold collide_convex(const ConvexView& a, const Pose& pa, const ConvexView& b, const Pose& pb,
                        Fixed margin) noexcept {
  using namespace convex::collide_detail;
  // The axis choice prefers the first shape's faces (as box_box does); solving every pair in one
  // order and mirroring makes collide_convex(b, a) collide_convex(a, b) mirrored, bit for bit.
  if (order_key(b, pb) >= order_key(a, pa)) return collide_ordered(a, pa, b, pb, margin);
  Manifold m = collide_ordered(b, pb, a, pa, margin);
  m.normal = -m.normal;
  for (std::uint8_t i = 0; i < m.count; ++i)
    m.points[i].feature = narrow::mirror_feature(m.points[i].feature);
  return m;
}

Manifold convex::collide_detail::collide_ordered(const ConvexView& a, const Pose& pa,
                                                 const ConvexView& b, const Pose& pb,
                                                 Fixed margin) noexcept {
  // In a's frame: a unrotated at the origin, b through one relative rotation (exact dots, one
  // rounding each); the manifold is moved back to the world at the end.
  const Mat3 to_a = transpose(pa.rotation);
  const Pose local_a{Vec3{}, Mat3::identity()};
  const Pose local_b{to_a * (pb.position - pa.position), to_a * pb.rotation};
  const convex::Body A = convex::make_body(a, local_a, Vec3{});
  const convex::Body B = convex::make_body(b, local_b, Vec3{});
  const Manifold m = collide_local(A, B, margin);
  return m.count > 0 ? narrow::to_world(m, pa) : Manifold{};
}

Manifold convex::collide_detail::collide_local(const Body& A, const Body& B,
                                               Fixed margin) noexcept {
  using namespace convex;
  const ConvexView& a = *A.view;
  const ConvexView& b = *B.view;
  if (length(B.position) - bounding_radius(a) - bounding_radius(b) > margin) return {};
  // Round cores and cylinders: GJK first. A cylinder's finite axis set can only prove separation,
  // never overlap (rim against rim may be apart along a direction no axis has), so SAT only
  // measures the penetration of cores GJK found to meet.
  const bool curved = a.kind == ConvexKind::cylinder || b.kind == ConvexKind::cylinder;
  if (is_round(a) || is_round(b) || curved) {
    const Closest c = gjk_closest(A, B);
    if (proven_apart(A, B, c)) return apart(A, B, c, margin);
  }
  const Sat s = separating_axes(A, B, margin);
  if (s.beyond) return {};
  if (!s.face_a.found && !s.face_b.found && !s.edge.found) {  // points / parallel segments meet
    const Vec3 n = unit_or(B.position - A.position, Vec3::unit_y());
    return manifold_from_faces(A, B, n, Reference::any, margin);
  }
  Choice choice = choose_axis(s, Fixed::one() + max(bounding_radius(a), bounding_radius(b)));
  if (curved && choice.axis.separation <= Fixed::zero() && !choice.axis.exact) {
    const Best refined = refine_axis(A, B, choice.axis);
    if (refined.normal != choice.axis.normal) choice.ref = Reference::any;
    choice.axis = refined;
  }
  Manifold m;
  if (axis_contact(A, B, choice, curved, margin, m)) return m;
  const Closest c = gjk_closest(A, B);
  if (c.overlap) return support_pair(A, B, choice.axis.normal, margin);
  return apart(A, B, c, margin);
}

}  // namespace detsim::sim_detail

// ConvexView: the per-kind geometry that the convex narrowphase reads (supports, supporting faces,
// the faces and edges of the separating axis test). One switch per question, one case per kind.
#include "convex.hpp"

#include <array>
#include <cstdint>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/vec3.hpp>

#include "../collide_util.hpp"

namespace detsim::sim_detail {

using namespace narrow;

ConvexView ConvexView::of(const Shape& s) noexcept {
  switch (s.type) {
    case ShapeType::box:
      return box(s.half_extents);
    case ShapeType::capsule:
      return capsule(s.radius, s.half_height);
    case ShapeType::cylinder:
      return cylinder(s.radius, s.half_height);
    default:
      return sphere(s.radius);
  }
}

namespace convex {

// Named, not anonymous: unity builds put the convex files in one translation unit.
namespace view_detail {

constexpr unsigned kRim = cylinder_rim_points;
constexpr unsigned kVertex = static_cast<unsigned>(Kind::vertex);
constexpr unsigned kEdge = static_cast<unsigned>(Kind::edge);
constexpr unsigned kFace = static_cast<unsigned>(Kind::face);

/// Rim directions at 22.5 degree steps, built from exact symmetries so that the four axis
/// directions are exact and opposite points are exact negatives.
struct RimTable {
  std::array<Vec3, kRim> at{};
  std::array<Vec3, kRim> side{};   ///< the prism's side k normal, between points k and k + 1
  std::array<Vec3, kRim> chord{};  ///< unit direction from point k to point k + 1
  RimTable() noexcept {
    const Fixed two = Fixed::from_int(2);
    const Fixed c = sqrt(two + Fixed::sqrt2()) >> 1;  // cos 22.5
    const Fixed s = sqrt(two - Fixed::sqrt2()) >> 1;  // sin 22.5
    const Fixed h = Fixed::sqrt2() >> 1;
    const std::array<std::array<Fixed, 2>, 4> quarter{
        {{Fixed::one(), Fixed::zero()}, {c, s}, {h, h}, {s, c}}};
    for (unsigned k = 0; k < kRim; ++k) {
      const auto& q = quarter[k % 4];
      Fixed x = q[0];
      Fixed z = q[1];
      for (unsigned turn = 0; turn < k / 4; ++turn) {  // +90 degrees: (x, z) -> (-z, x)
        const Fixed t = x;
        x = -z;
        z = t;
      }
      at[k] = Vec3{x, Fixed::zero(), z};
    }
    for (unsigned k = 0; k < kRim; ++k) {
      side[k] = normalize(at[k] + at[(k + 1) % kRim]);
      chord[k] = normalize(at[(k + 1) % kRim] - at[k]);
    }
  }
};

const RimTable& rim_table() noexcept {
  static const RimTable table;
  return table;
}

std::uint16_t box_corner_feature(unsigned bits) noexcept {
  return box_vertex({(bits & 1U) != 0, (bits & 2U) != 0, (bits & 4U) != 0});
}

Vec3 box_corner(Vec3 h, unsigned bits) noexcept {
  return {signed_value((bits & 1U) != 0, h.x), signed_value((bits & 2U) != 0, h.y),
          signed_value((bits & 4U) != 0, h.z)};
}

/// The edge of a box between corners u and w (which differ in one bit).
std::uint16_t box_edge_between(unsigned u, unsigned w) noexcept {
  const unsigned diff = u ^ w;
  const int axis = diff == 1U ? 0 : (diff == 2U ? 1 : 2);
  return box_edge(axis, {(u & 1U) != 0, (u & 2U) != 0, (u & 4U) != 0});
}

/// The index of hull edge (u, w) in the (a, b)-sorted edge list (binary search), or 0.
unsigned hull_edge_index(const Hull& hull, std::uint16_t u, std::uint16_t w) noexcept {
  const std::uint16_t a = u < w ? u : w;
  const std::uint16_t b = u < w ? w : u;
  std::size_t lo = 0;
  std::size_t hi = hull.edges.size();
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    const HullEdge& e = hull.edges[mid];
    if (e.a < a || (e.a == a && e.b < b)) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return static_cast<unsigned>(lo);
}

void push(Face& f, Vec3 p, std::uint16_t vertex, std::uint16_t edge) noexcept {
  if (f.count >= max_face_points) return;
  f.points[f.count] = p;
  f.vertex[f.count] = vertex;
  f.edge[f.count] = edge;
  ++f.count;
}

Face box_face_toward(Vec3 h, Vec3 d) noexcept {
  const Vec3 m = abs_components(d);
  int k = 0;
  if (m.y > component(m, k)) k = 1;
  if (m.z > component(m, k)) k = 2;
  const bool positive = component(d, k) >= Fixed::zero();
  const unsigned ka = static_cast<unsigned>((k + 1) % 3);
  const unsigned kb = static_cast<unsigned>((k + 2) % 3);
  // (+,+), (-,+), (-,-), (+,-) over (k+1, k+2) is counter-clockwise about +k.
  constexpr std::array<std::array<bool, 2>, 4> order{
      {{true, true}, {false, true}, {false, false}, {true, false}}};
  std::array<unsigned, 4> bits{};
  for (unsigned i = 0; i < 4; ++i) {
    const unsigned j = positive ? i : 3 - i;
    bits[i] = (positive ? 1U << static_cast<unsigned>(k) : 0U) | (order[j][0] ? 1U << ka : 0U) |
              (order[j][1] ? 1U << kb : 0U);
  }
  Face f;
  f.normal = axis_vector(k, positive);
  f.feature = box_face(k, positive);
  for (unsigned i = 0; i < 4; ++i) {
    push(f, box_corner(h, bits[i]), box_corner_feature(bits[i]),
         box_edge_between(bits[i], bits[(i + 1) % 4]));
  }
  return f;
}

/// The face around the support vertex that most faces d (ties to the lower index): the most
/// aligned face of all may not touch the support vertex, and then its edges are not the nearest.
Face hull_face_toward(const Hull& hull, Vec3 d) noexcept {
  Face f;
  if (hull.faces.empty()) return f;
  const std::uint16_t top = hull_support(hull, d);
  std::size_t best = hull.faces.size();
  Fixed best_dot;
  for (std::size_t i = 0; i < hull.faces.size(); ++i) {
    const HullFace& face = hull.faces[i];
    bool around = false;
    for (unsigned k = 0; k < face.count && !around; ++k)
      around = hull.face_vertices[face.first + k] == top;
    const Fixed x = dot(face.normal, d);
    if (around && (best == hull.faces.size() || x > best_dot)) {
      best_dot = x;
      best = i;
    }
  }
  if (best == hull.faces.size()) best = 0;  // a malformed hull: any face
  const HullFace& face = hull.faces[best];
  f.normal = face.normal;
  f.feature = convex_feature(kFace, static_cast<unsigned>(best));
  for (unsigned i = 0; i < face.count && i < max_face_points; ++i) {
    const std::uint16_t v = hull.face_vertices[face.first + i];
    const unsigned next = (i + 1 == face.count || i + 1 == max_face_points) ? 0 : i + 1;
    const std::uint16_t w = hull.face_vertices[face.first + next];
    push(f, hull.vertices[v], convex_feature(kVertex, v),
         convex_feature(kEdge, hull_edge_index(hull, v, w)));
  }
  return f;
}

/// The horizontal unit direction of d (local y is the axis), or zero when d is vertical.
Vec3 radial(Vec3 d) noexcept {
  return normalize(Vec3{d.x, Fixed::zero(), d.z});
}

Face cylinder_face_toward(Fixed r, Fixed h, Vec3 d) noexcept {
  Face f;
  const Fixed side2 = d.x * d.x + d.z * d.z;
  if (d.y * d.y >= side2) {  // nearer the axis than the side: a cap
    const bool top = d.y >= Fixed::zero();
    f.normal = axis_vector(1, top);
    f.feature = convex_feature(kFace, top ? 0U : 1U);
    const RimTable& rim = rim_table();
    for (unsigned i = 0; i < kRim; ++i) {
      const unsigned k = top ? i : kRim - 1 - i;  // listed in one turning order on either cap
      const unsigned k_next = top ? (k + 1) % kRim : (k + kRim - 1) % kRim;
      const unsigned chord = top ? k : k_next;  // rim chord c joins points c and c + 1
      Vec3 p = rim.at[k] * r;
      p.y = signed_value(top, h);
      push(f, p, convex_feature(kVertex, top ? k : kRim + k),
           convex_feature(kEdge, top ? 1 + chord : 1 + kRim + chord));
    }
    return f;
  }
  const Vec3 u = radial(d) * r;
  f.feature = convex_feature(kEdge, 0);
  push(f, Vec3{u.x, -h, u.z}, convex_feature(kVertex, 2 * kRim), f.feature);
  push(f, Vec3{u.x, h, u.z}, convex_feature(kVertex, 2 * kRim + 1), f.feature);
  return f;
}

Face capsule_face_toward(Fixed half, Vec3 d) noexcept {
  Face f;
  const Vec3 top{Fixed::zero(), half, Fixed::zero()};
  if (half > Fixed::zero() && d.y * d.y < flat_sin2) {
    f.feature = capsule_core;
    push(f, -top, capsule_end(false), capsule_core);
    push(f, top, capsule_end(true), capsule_core);
    return f;
  }
  const bool up = d.y >= Fixed::zero();
  f.feature = capsule_end(up);
  push(f, up ? top : -top, f.feature, f.feature);
  return f;
}

/// Box edge i = 4 axis + bits: along `axis`, on the sides (axis + 1, axis + 2) given by bits 0, 1.
SatEdge box_sat_edge(Vec3 h, unsigned i) noexcept {
  const int axis = static_cast<int>(i / 4);
  const bool s1 = (i & 1U) != 0;
  const bool s2 = (i & 2U) != 0;
  Signs s{};
  s[static_cast<unsigned>((axis + 1) % 3)] = s1;
  s[static_cast<unsigned>((axis + 2) % 3)] = s2;
  const unsigned lo = (s[0] ? 1U : 0U) | (s[1] ? 2U : 0U) | (s[2] ? 4U : 0U);
  SatEdge e;
  e.p0 = box_corner(h, lo);
  e.p1 = box_corner(h, lo | (1U << static_cast<unsigned>(axis)));
  e.direction = axis_vector(axis);
  e.n0 = axis_vector((axis + 1) % 3, s1);
  e.n1 = axis_vector((axis + 2) % 3, s2);
  e.feature = box_edge(axis, s);
  return e;
}

/// Cylinder edge i of its 16-gon prism: the +y rim's chord k (i = k), the -y rim's (16 + k), or
/// the side line through rim point k (32 + k), the one edge of the true cylinder among them.
SatEdge cylinder_sat_edge(const ConvexView& v, unsigned i) noexcept {
  const RimTable& rim = rim_table();
  const unsigned k = i % kRim;
  const Vec3 p = rim.at[k] * v.radius;
  const Vec3 q = rim.at[(k + 1) % kRim] * v.radius;
  const Vec3 up{Fixed::zero(), v.half_height, Fixed::zero()};
  SatEdge e;
  e.exact = false;
  e.feature = convex_feature(kEdge, 1 + i);
  e.n1 = rim.side[k];
  if (i < 2 * kRim) {
    const bool top = i < kRim;
    e.p0 = top ? p + up : p - up;
    e.p1 = top ? q + up : q - up;
    e.direction = rim.chord[k];
    e.n0 = axis_vector(1, top);
    return e;
  }
  e.p0 = p - up;
  e.p1 = p + up;
  e.direction = Vec3::unit_y();
  e.n0 = rim.side[(k + kRim - 1) % kRim];
  e.exact = true;
  return e;
}

}  // namespace view_detail

using namespace view_detail;

Vec3 rim_direction(unsigned i) noexcept {
  return rim_table().at[i % kRim];
}

Fixed core_radius(const ConvexView& v) noexcept {
  return v.kind == ConvexKind::sphere || v.kind == ConvexKind::capsule ? v.radius : Fixed::zero();
}

Fixed bounding_radius(const ConvexView& v) noexcept {
  switch (v.kind) {
    case ConvexKind::sphere:
      return v.radius;
    case ConvexKind::capsule:
      return v.radius + v.half_height;
    case ConvexKind::box:
      return length(v.half_extents);
    case ConvexKind::cylinder:
      return length(Vec3{v.radius, v.half_height, Fixed::zero()});
    case ConvexKind::hull:
      return v.hull->bounding_radius;
  }
  return Fixed::zero();
}

SupportPoint core_support(const ConvexView& v, Vec3 d) noexcept {
  switch (v.kind) {
    case ConvexKind::sphere:
      return {Vec3{}, whole_shape};
    case ConvexKind::capsule: {
      const bool up = d.y >= Fixed::zero();
      return {Vec3{Fixed::zero(), signed_value(up, v.half_height), Fixed::zero()}, capsule_end(up)};
    }
    case ConvexKind::box: {
      const unsigned bits = (d.x >= Fixed::zero() ? 1U : 0U) | (d.y >= Fixed::zero() ? 2U : 0U) |
                            (d.z >= Fixed::zero() ? 4U : 0U);
      return {box_corner(v.half_extents, bits), box_corner_feature(bits)};
    }
    case ConvexKind::cylinder: {
      const bool top = d.y >= Fixed::zero();
      Vec3 p = radial(d) * v.radius;
      p.y = signed_value(top, v.half_height);
      const bool on_axis = p.x == Fixed::zero() && p.z == Fixed::zero();
      return {p, on_axis ? convex_feature(kFace, top ? 0U : 1U)
                         : convex_feature(kVertex, 2 * kRim + 2 + (top ? 1U : 0U))};
    }
    case ConvexKind::hull: {
      const std::uint16_t i = hull_support(*v.hull, d);
      return {v.hull->vertices[i], convex_feature(kVertex, i)};
    }
  }
  return {};
}

Vec3 support(const ConvexView& v, const Pose& pose, Vec3 direction) noexcept {
  const SupportPoint s = core_support(v, to_local(pose.rotation, direction));
  const Vec3 p = pose.position + pose.rotation * s.point;
  const Fixed r = core_radius(v);
  return r == Fixed::zero() ? p : p + normalize(direction) * r;
}

Face supporting_face(const ConvexView& v, Vec3 direction) noexcept {
  const Vec3 d = normalize(direction);
  switch (v.kind) {
    case ConvexKind::sphere: {
      Face f;
      f.feature = whole_shape;
      push(f, Vec3{}, whole_shape, whole_shape);
      return f;
    }
    case ConvexKind::capsule:
      return capsule_face_toward(v.half_height, d);
    case ConvexKind::box:
      return box_face_toward(v.half_extents, d);
    case ConvexKind::cylinder:
      return cylinder_face_toward(v.radius, v.half_height, d);
    case ConvexKind::hull:
      return hull_face_toward(*v.hull, d);
  }
  return {};
}

Face supporting_face(const ConvexView& v, const Pose& pose, Vec3 direction, Vec3 origin) noexcept {
  Face f = supporting_face(v, to_local(pose.rotation, direction));
  const Vec3 offset = pose.position - origin;
  for (unsigned i = 0; i < f.count; ++i)
    f.points[i] = offset + pose.rotation * f.points[i];
  if (f.normal != Vec3{}) f.normal = unit_or(pose.rotation * f.normal, f.normal);
  return f;
}

unsigned sat_face_count(const ConvexView& v) noexcept {
  switch (v.kind) {
    case ConvexKind::box:
      return 6;
    case ConvexKind::cylinder:
      return 2 + kRim;
    case ConvexKind::hull:
      return static_cast<unsigned>(v.hull->faces.size());
    default:
      return 0;
  }
}

SatFace sat_face(const ConvexView& v, unsigned i) noexcept {
  switch (v.kind) {
    case ConvexKind::box:
      return {axis_vector(static_cast<int>(i / 2), i % 2 == 0), true};
    case ConvexKind::cylinder:
      if (i < 2) return {axis_vector(1, i == 0), true};
      return {rim_table().side[(i - 2) % kRim], false};
    case ConvexKind::hull:
      return {v.hull->faces[i].normal, true};
    default:
      return {};
  }
}

unsigned sat_edge_count(const ConvexView& v) noexcept {
  switch (v.kind) {
    case ConvexKind::capsule:
      return 1;
    case ConvexKind::box:
      return 12;
    case ConvexKind::cylinder:
      return 3 * kRim;
    case ConvexKind::hull:
      return static_cast<unsigned>(v.hull->edges.size());
    default:
      return 0;
  }
}

SatEdge sat_edge(const ConvexView& v, unsigned i) noexcept {
  switch (v.kind) {
    case ConvexKind::capsule: {
      SatEdge e;
      e.p0 = Vec3{Fixed::zero(), -v.half_height, Fixed::zero()};
      e.p1 = -e.p0;
      e.direction = Vec3::unit_y();
      e.feature = capsule_core;
      e.circle = true;
      return e;
    }
    case ConvexKind::box:
      return box_sat_edge(v.half_extents, i);
    case ConvexKind::cylinder:
      return cylinder_sat_edge(v, i);
    case ConvexKind::hull: {
      const HullEdge& h = v.hull->edges[i];
      SatEdge e;
      e.p0 = v.hull->vertices[h.a];
      e.p1 = v.hull->vertices[h.b];
      e.direction = h.direction;
      e.n0 = v.hull->faces[h.face_0].normal;
      e.n1 = v.hull->faces[h.face_1].normal;
      e.feature = convex_feature(kEdge, i);
      return e;
    }
    default:
      return {};
  }
}

}  // namespace convex

}  // namespace detsim::sim_detail

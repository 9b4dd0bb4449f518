// GJK closest points of two convex cores (Gilbert, Johnson and Keerthi 1988), with the simplex's
// closest point found by Voronoi regions (Ericson, Real-Time Collision Detection 5.1.5-5.1.6).
//
// Precision: simplex vertices are differences of support points, bounded by the shapes' sizes and
// distance. Interior solutions use normalize() of cross products (accurate for any magnitude), so
// only the region decisions use products of squared lengths, which are exact for metre-sized
// shapes and lose bits only below ~1 cm. The iteration is capped (gjk_iterations): a cylinder's
// curved side converges linearly, polytopes end when a support point repeats.
#include <array>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/vec3.hpp>

#include "../collide_util.hpp"
#include "convex_internal.hpp"

namespace detsim::sim_detail::convex {

Body make_body(const ConvexView& v, const Pose& pose, Vec3 origin) noexcept {
  return {&v,   pose.rotation, pose.position - origin,           core_radius(v),
          pose, origin,        pose.rotation == Mat3::identity()};
}

SupportPoint support_at(const Body& b, Vec3 direction) noexcept {
  if (b.unrotated) {
    SupportPoint s = core_support(*b.view, direction);
    s.point += b.position;
    return s;
  }
  SupportPoint s = core_support(*b.view, narrow::to_local(b.rotation, direction));
  s.point = b.position + b.rotation * s.point;
  return s;
}

Face face_at(const Body& b, Vec3 direction) noexcept {
  if (!b.unrotated) return supporting_face(*b.view, b.pose, direction, b.origin);
  Face f = supporting_face(*b.view, direction);
  for (unsigned i = 0; i < f.count; ++i)
    f.points[i] += b.position;
  return f;
}

namespace gjk_detail {

struct Vertex {
  Vec3 w;  ///< on_b - on_a: a point of the Minkowski difference of the cores
  Vec3 on_a;
  Vec3 on_b;
};

struct Simplex {
  std::array<Vertex, 4> v{};
  std::array<Fixed, 4> weight{};
  int n = 0;
  Vec3 closest;  ///< sum of weight * w
  bool inside = false;
};

Simplex make(std::initializer_list<Vertex> vs, std::initializer_list<Fixed> ws) noexcept {
  Simplex s;
  for (const Vertex& x : vs)
    s.v[static_cast<unsigned>(s.n++)] = x;
  int i = 0;
  for (const Fixed x : ws)
    s.weight[static_cast<unsigned>(i++)] = x;
  for (int k = 0; k < s.n; ++k)
    s.closest += s.v[static_cast<unsigned>(k)].w * s.weight[static_cast<unsigned>(k)];
  return s;
}

Simplex on_segment(const Vertex& a, const Vertex& b) noexcept {
  const Vec3 ab = b.w - a.w;
  const Fixed len2 = dot(ab, ab);
  const Fixed t = len2 > Fixed::zero() ? -dot(a.w, ab) / len2 : Fixed::zero();
  if (t <= Fixed::zero()) return make({a}, {Fixed::one()});
  if (t >= Fixed::one()) return make({b}, {Fixed::one()});
  return make({a, b}, {Fixed::one() - t, t});
}

/// The interior solution of a triangle: the origin's projection with barycentric weights.
Simplex triangle_interior(const Vertex& a, const Vertex& b, const Vertex& c) noexcept {
  const Vec3 ab = b.w - a.w;
  const Vec3 ac = c.w - a.w;
  const Vec3 n = normalize(cross(ab, ac));
  const Fixed total = dot(cross(ab, ac), n);
  if (total <= Fixed::zero()) return on_segment(a, b);  // degenerate: an edge will do
  const Vec3 p = n * dot(a.w, n);
  const Fixed s = dot(cross(p - a.w, ac), n) / total;
  const Fixed t = dot(cross(ab, p - a.w), n) / total;
  return make({a, b, c}, {Fixed::one() - s - t, s, t});
}

Simplex on_triangle(const Vertex& a, const Vertex& b, const Vertex& c) noexcept {
  const Vec3 ab = b.w - a.w;
  const Vec3 ac = c.w - a.w;
  const Fixed d1 = -dot(ab, a.w);
  const Fixed d2 = -dot(ac, a.w);
  if (d1 <= Fixed::zero() && d2 <= Fixed::zero()) return make({a}, {Fixed::one()});
  const Fixed d3 = -dot(ab, b.w);
  const Fixed d4 = -dot(ac, b.w);
  if (d3 >= Fixed::zero() && d4 <= d3) return make({b}, {Fixed::one()});
  const Fixed vc = d1 * d4 - d3 * d2;
  if (vc <= Fixed::zero() && d1 >= Fixed::zero() && d3 <= Fixed::zero()) return on_segment(a, b);
  const Fixed d5 = -dot(ab, c.w);
  const Fixed d6 = -dot(ac, c.w);
  if (d6 >= Fixed::zero() && d5 <= d6) return make({c}, {Fixed::one()});
  const Fixed vb = d5 * d2 - d1 * d6;
  if (vb <= Fixed::zero() && d2 >= Fixed::zero() && d6 <= Fixed::zero()) return on_segment(a, c);
  const Fixed va = d3 * d6 - d5 * d4;
  if (va <= Fixed::zero() && d4 - d3 >= Fixed::zero() && d5 - d6 >= Fixed::zero())
    return on_segment(b, c);
  return triangle_interior(a, b, c);
}

/// Whether the origin may lie beyond the face (p, q, r) of a tetrahedron whose fourth vertex is
/// `opposite`: on the other side of its plane, on the plane, or the tetrahedron too flat (fourth
/// vertex within 2^-24 m of the plane, as when four support points lie on one face of a box or a
/// cylinder's cap) or the face a sliver to tell. Only a tetrahedron that strictly holds the origin
/// means overlap.
bool origin_outside(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& opposite) noexcept {
  const Vec3 c = cross(q - p, r - p);
  // A sliver (a curved side's support points crowd together, sin of its angle below 2^-8): its
  // normal is mostly rounding.
  if (length_squared(c) <= (length_squared(q - p) * length_squared(r - p)) >> 16) return true;
  const Vec3 n = normalize(c);
  const Fixed origin_side = -dot(n, p);
  const Fixed opposite_side = dot(n, opposite - p);
  const Fixed flat = Fixed::from_raw(Fixed::one_raw >> 24);
  if (abs(opposite_side) <= flat || origin_side == Fixed::zero()) return true;
  return (origin_side > Fixed::zero()) != (opposite_side > Fixed::zero());
}

Simplex on_tetrahedron(const Simplex& s) noexcept {
  constexpr std::array<std::array<unsigned, 4>, 4> faces{
      {{0, 1, 2, 3}, {0, 3, 1, 2}, {0, 2, 3, 1}, {1, 3, 2, 0}}};
  Simplex best;
  bool any = false;
  Fixed best_d2 = Fixed::max();
  for (const auto& f : faces) {
    const Vertex& p = s.v[f[0]];
    const Vertex& q = s.v[f[1]];
    const Vertex& r = s.v[f[2]];
    if (!origin_outside(p.w, q.w, r.w, s.v[f[3]].w)) continue;
    const Simplex t = on_triangle(p, q, r);
    const Fixed d2 = dot(t.closest, t.closest);
    if (!any || d2 < best_d2) {
      best = t;
      best_d2 = d2;
      any = true;
    }
  }
  if (!any) {
    best = s;
    best.inside = true;
  }
  return best;
}

Simplex solve(const Simplex& s) noexcept {
  switch (s.n) {
    case 1:
      return make({s.v[0]}, {Fixed::one()});
    case 2:
      return on_segment(s.v[0], s.v[1]);
    case 3:
      return on_triangle(s.v[0], s.v[1], s.v[2]);
    default:
      return on_tetrahedron(s);
  }
}

Vertex support_of_difference(const Body& a, const Body& b, Vec3 direction) noexcept {
  const Vec3 on_a = support_at(a, -direction).point;
  const Vec3 on_b = support_at(b, direction).point;
  return {on_b - on_a, on_a, on_b};
}

}  // namespace gjk_detail

Closest gjk_closest(const Body& a, const Body& b) noexcept {
  using namespace gjk_detail;
  Vec3 start = b.position - a.position;
  if (start == Vec3{}) start = Vec3::unit_x();
  Simplex s = make({support_of_difference(a, b, -start)}, {Fixed::one()});
  const Fixed floor = Fixed::from_raw(4);
  for (int iteration = 0; iteration < gjk_iterations; ++iteration) {
    const Vec3 v = s.closest;
    const Fixed vv = dot(v, v);
    if (vv == Fixed::zero()) {
      s.inside = true;
      break;
    }
    const Vertex w = support_of_difference(a, b, -v);
    if (vv - dot(v, w.w) <= (vv >> 28) + floor) break;  // no point is much nearer
    bool repeated = false;
    for (int i = 0; i < s.n; ++i)
      repeated = repeated || s.v[static_cast<unsigned>(i)].w == w.w;
    if (repeated) break;
    Simplex grown = s;
    grown.v[static_cast<unsigned>(grown.n++)] = w;
    const Simplex next = solve(grown);
    if (next.inside) {
      s = next;
      break;
    }
    if (dot(next.closest, next.closest) >= vv) break;  // no progress: keep the better simplex
    s = next;
  }
  Closest out;
  out.overlap = s.inside;
  for (int i = 0; i < s.n && !s.inside; ++i) {
    const unsigned k = static_cast<unsigned>(i);
    out.on_a += s.v[k].on_a * s.weight[k];
    out.on_b += s.v[k].on_b * s.weight[k];
  }
  out.distance = s.inside ? Fixed::zero() : length(s.closest);
  if (out.distance < Fixed::from_raw(Fixed::one_raw >> 20)) out.overlap = true;
  return out;
}

}  // namespace detsim::sim_detail::convex

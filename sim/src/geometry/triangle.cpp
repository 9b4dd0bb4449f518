// The per-triangle tests shared by meshes and heightfields (triangle.hpp).
#include "triangle.hpp"

#include <bit>

#include <detsim/fixed/exact_sum.hpp>
#include <detsim/fixed/math.hpp>

namespace detsim::sim_detail {

namespace {

/// The exact a_i b_j - a_j b_i (a Q64.64 value of at most ~2^95 here: differences of coordinates
/// within +-10^4 m are below 2^47 raw).
detail::ProductSum exact_minor(Fixed ai, Fixed bj, Fixed aj, Fixed bi) noexcept {
  detail::ProductSum s;
  s.add_product(ai.raw(), bj.raw());
  s.sub_product(aj.raw(), bi.raw());
  return s;
}

/// The degenerate threshold: 2^-24 m^2 as a Q64.64 magnitude.
constexpr unsigned min_normal_bits = 64 - 24;

/// The lexicographic order on raw coordinates: a total order on points.
constexpr bool before(Vec3 a, Vec3 b) noexcept {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

/// The side of the line p + v t relative to the directed edge a -> b: the triple product
/// (a - p) . ((b - p) x v), with the dot product's sum rounded once.
Fixed side(Vec3 p, Vec3 v, Vec3 a, Vec3 b) noexcept {
  return DotSum{}.add(a - p, cross(b - p, v)).result();
}

/// side() computed from the lower endpoint, negated for the reversed direction: the two
/// triangles of a shared edge see exactly opposite values (watertightness).
Fixed edge_side(Vec3 p, Vec3 v, Vec3 a, Vec3 b) noexcept {
  return before(b, a) ? -side(p, v, b, a) : side(p, v, a, b);
}

}  // namespace

std::optional<Vec3> triangle_normal(Vec3 a, Vec3 b, Vec3 c) noexcept {
  const Vec3 u = b - a;
  const Vec3 w = c - a;
  const std::array<detail::ProductSum, 3> n = {exact_minor(u.y, w.z, u.z, w.y),
                                               exact_minor(u.z, w.x, u.x, w.z),
                                               exact_minor(u.x, w.y, u.y, w.x)};
  // The magnitudes fit in 128 bits (|n_i| < 2^96); shift them together until the largest fits in
  // 62 bits, keep the signs, and let normalize() (scale-invariant) do the rest.
  std::array<wide::U128, 3> m{};
  unsigned bits = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    m[i] = n[i].magnitude_128();
    const unsigned len = m[i].hi != 0 ? 128U - static_cast<unsigned>(std::countl_zero(m[i].hi))
                                      : 64U - static_cast<unsigned>(std::countl_zero(m[i].lo));
    bits = len > bits ? len : bits;
  }
  if (bits <= min_normal_bits) return std::nullopt;
  const unsigned shift = bits > 62 ? bits - 62 : 0;
  Vec3 scaled;
  for (std::size_t i = 0; i < 3; ++i) {
    const std::uint64_t mag = wide::shr(m[i], shift).lo;
    const auto value = static_cast<std::int64_t>(mag);
    const Fixed f = Fixed::from_raw(n[i].negative() ? -value : value);
    if (i == 0) scaled.x = f;
    if (i == 1) scaled.y = f;
    if (i == 2) scaled.z = f;
  }
  return normalize(scaled);
}

bool ray_crosses_triangle(Vec3 p, Vec3 v, Vec3 a, Vec3 b, Vec3 c) noexcept {
  const Fixed zero = Fixed::zero();
  const Fixed e0 = edge_side(p, v, a, b);
  const Fixed e1 = edge_side(p, v, b, c);
  if ((e0 > zero && e1 < zero) || (e0 < zero && e1 > zero)) return false;
  const Fixed e2 = edge_side(p, v, c, a);
  const bool none_negative = e0 >= zero && e1 >= zero && e2 >= zero;
  const bool none_positive = e0 <= zero && e1 <= zero && e2 <= zero;
  // All three zero: the line lies in the triangle's plane (or the triangle is degenerate).
  return (none_negative || none_positive) && !(none_negative && none_positive);
}

std::optional<Fixed> ray_plane_t(Vec3 p, Vec3 v, Vec3 a, Vec3 n, Fixed max_t) noexcept {
  const Fixed along = dot(v, n);
  if (along == Fixed::zero()) return std::nullopt;
  const Fixed height = dot(a - p, n);  // signed distance of the plane from p, along n
  // t = height / along >= 0 needs the same sign (or a zero height); checked before dividing.
  if (height != Fixed::zero() && (height < Fixed::zero()) != (along < Fixed::zero())) {
    return std::nullopt;
  }
  const Fixed t = height / along;
  if (t > max_t) return std::nullopt;
  return t;
}

std::optional<TriangleHit> ray_triangle(Vec3 p, Vec3 v, Vec3 a, Vec3 b, Vec3 c, Vec3 n,
                                        std::uint32_t triangle, Fixed max_t) noexcept {
  if (!ray_crosses_triangle(p, v, a, b, c)) return std::nullopt;
  return ray_hit_plane(p, v, a, n, triangle, max_t);
}

std::optional<TriangleHit> ray_hit_plane(Vec3 p, Vec3 v, Vec3 a, Vec3 n, std::uint32_t triangle,
                                         Fixed max_t) noexcept {
  const auto t = ray_plane_t(p, v, a, n, max_t);
  if (!t) return std::nullopt;
  const Vec3 facing = dot(v, n) < Fixed::zero() ? n : -n;
  return TriangleHit{*t, Vec3Sum{p}.add(*t, v).result(), facing, triangle};
}

EdgeKind classify_edge(Vec3 normal, Vec3 on_edge, Vec3 neighbour_normal,
                       Vec3 neighbour_far_vertex) noexcept {
  // cos(angle) >= 1 - 2^-24, i.e. angle <= ~2^-11.5 rad: the unit normals' rounding (~2^-31) is
  // far below the threshold, so the answer does not hang on it.
  const Fixed flat_cos = Fixed::one() - Fixed::from_raw(Fixed::one_raw >> 24);
  if (dot(normal, neighbour_normal) >= flat_cos) return EdgeKind::flat;
  const Fixed height = dot(neighbour_far_vertex - on_edge, normal);
  if (height < Fixed::zero()) return EdgeKind::convex;
  if (height > Fixed::zero()) return EdgeKind::concave;
  return EdgeKind::flat;
}

Bounds triangle_bounds(Vec3 a, Vec3 b, Vec3 c) noexcept {
  return {{min(a.x, min(b.x, c.x)), min(a.y, min(b.y, c.y)), min(a.z, min(b.z, c.z))},
          {max(a.x, max(b.x, c.x)), max(a.y, max(b.y, c.y)), max(a.z, max(b.z, c.z))}};
}

}  // namespace detsim::sim_detail

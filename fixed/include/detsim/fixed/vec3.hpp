// detsim::Vec3: a 3D vector of Fixed (positions, velocities, axes).
//
// Componentwise operations (+, -, scalar * and /) behave exactly like the Fixed operators: each
// component is rounded to nearest (ties to even) and saturated on its own. Products of vectors
// (dot, cross, length_squared) are different: each result component is the exact sum of exact
// 128-bit products, rounded once (ties to even) and then saturated, so there is no intermediate
// overflow and no second rounding at any magnitude. length, normalize and distance (defined in
// vector.cpp) use a correctly rounded integer square root of the exact sum of squares.
#pragma once

#include <detsim/fixed/exact_sum.hpp>
#include <detsim/fixed/fixed.hpp>

namespace detsim {

/// A 3D vector of Fixed. A plain aggregate: `Vec3{x, y, z}`; the default is the zero vector.
struct Vec3 {
  Fixed x;
  Fixed y;
  Fixed z;

  [[nodiscard]] static constexpr Vec3 zero() noexcept { return {}; }
  [[nodiscard]] static constexpr Vec3 unit_x() noexcept { return {Fixed::one(), {}, {}}; }
  [[nodiscard]] static constexpr Vec3 unit_y() noexcept { return {{}, Fixed::one(), {}}; }
  [[nodiscard]] static constexpr Vec3 unit_z() noexcept { return {{}, {}, Fixed::one()}; }

  /// Bitwise (and so value) equality of all three components.
  friend constexpr bool operator==(Vec3, Vec3) noexcept = default;

  constexpr Vec3& operator+=(Vec3 b) noexcept;
  constexpr Vec3& operator-=(Vec3 b) noexcept;
  constexpr Vec3& operator*=(Fixed s) noexcept;
  constexpr Vec3& operator/=(Fixed s) noexcept;
};

/// Componentwise sum, each component saturated like Fixed +.
[[nodiscard]] constexpr Vec3 operator+(Vec3 a, Vec3 b) noexcept {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
/// Componentwise difference, each component saturated like Fixed -.
[[nodiscard]] constexpr Vec3 operator-(Vec3 a, Vec3 b) noexcept {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
/// Componentwise negation; a Fixed::min() component becomes Fixed::max().
[[nodiscard]] constexpr Vec3 operator-(Vec3 a) noexcept {
  return {-a.x, -a.y, -a.z};
}
/// Each component times s, rounded (ties to even) and saturated like Fixed *.
[[nodiscard]] constexpr Vec3 operator*(Vec3 a, Fixed s) noexcept {
  return {a.x * s, a.y * s, a.z * s};
}
[[nodiscard]] constexpr Vec3 operator*(Fixed s, Vec3 a) noexcept {
  return a * s;
}
/// Each component divided by s, rounded and saturated like Fixed /; dividing by zero gives max(),
/// min() or 0 per component by the sign of that component.
[[nodiscard]] constexpr Vec3 operator/(Vec3 a, Fixed s) noexcept {
  return {a.x / s, a.y / s, a.z / s};
}

constexpr Vec3& Vec3::operator+=(Vec3 b) noexcept {
  return *this = *this + b;
}
constexpr Vec3& Vec3::operator-=(Vec3 b) noexcept {
  return *this = *this - b;
}
constexpr Vec3& Vec3::operator*=(Fixed s) noexcept {
  return *this = *this * s;
}
constexpr Vec3& Vec3::operator/=(Fixed s) noexcept {
  return *this = *this / s;
}

/// a . b: the exact sum of the exact products, rounded once (ties to even), then saturated. No
/// intermediate overflow for any inputs: dot((2^20, 2^20, 0), (2^20, -2^20, 0)) == 0.
[[nodiscard]] constexpr Fixed dot(Vec3 a, Vec3 b) noexcept {
  detail::ProductSum s;
  s.add_product(a.x.raw(), b.x.raw());
  s.add_product(a.y.raw(), b.y.raw());
  s.add_product(a.z.raw(), b.z.raw());
  return s.to_fixed();
}

/// a x b (right-handed). Each component is the exact a_i b_j - a_j b_i rounded once and saturated,
/// so cross(a, a) == 0 and cross(b, a) == -cross(a, b) exactly for all a, b, except where a
/// component saturates: max() on one side is min() (not -max()) on the other.
[[nodiscard]] constexpr Vec3 cross(Vec3 a, Vec3 b) noexcept {
  const auto component = [](Fixed p, Fixed q, Fixed r, Fixed t) {
    detail::ProductSum s;  // p q - r t
    s.add_product(p.raw(), q.raw());
    s.sub_product(r.raw(), t.raw());
    return s.to_fixed();
  };
  return {component(a.y, b.z, a.z, b.y), component(a.z, b.x, a.x, b.z),
          component(a.x, b.y, a.y, b.x)};
}

/// A sum of dot products rounded once: `DotSum{}.add(a, b).add(c, d).result()` is a . b + c . d
/// summed exactly, then rounded to nearest (ties to even) and saturated, where
/// dot(a, b) + dot(c, d) rounds twice and can saturate in between. Holds up to 2^61 terms.
class DotSum {
 public:
  constexpr DotSum& add(Vec3 a, Vec3 b) noexcept {
    sum_.add_product(a.x.raw(), b.x.raw());
    sum_.add_product(a.y.raw(), b.y.raw());
    sum_.add_product(a.z.raw(), b.z.raw());
    return *this;
  }
  [[nodiscard]] constexpr Fixed result() const noexcept { return sum_.to_fixed(); }

 private:
  detail::ProductSum sum_;
};

/// A vector plus scaled vectors rounded once per component: `Vec3Sum{v}.add(s, d).result()` is
/// v + s d with each component summed exactly, then rounded to nearest (ties to even) and
/// saturated (a fused multiply-add), where v + d * s rounds the products first and can saturate in
/// between. Holds up to 2^61 terms.
class Vec3Sum {
 public:
  constexpr Vec3Sum() noexcept = default;
  /// Starts from v exactly.
  explicit constexpr Vec3Sum(Vec3 v) noexcept : base_(v) {}
  /// Adds s d.
  constexpr Vec3Sum& add(Fixed s, Vec3 d) noexcept {
    x_.add_product(s.raw(), d.x.raw());
    y_.add_product(s.raw(), d.y.raw());
    z_.add_product(s.raw(), d.z.raw());
    return *this;
  }
  [[nodiscard, gnu::always_inline]] constexpr Vec3 result() const noexcept {
    return {x_.to_fixed_plus(base_.x.raw()), y_.to_fixed_plus(base_.y.raw()),
            z_.to_fixed_plus(base_.z.raw())};
  }

 private:
  Vec3 base_;  // kept apart from the products: rounding adds it without a 128-bit term
  detail::ProductSum x_;
  detail::ProductSum y_;
  detail::ProductSum z_;
};

/// |v|^2, exact then rounded once (ties to even); saturates to Fixed::max() when |v|^2 >= 2^31
/// (any component of magnitude 2^15.5 or more can do that). Use length() for large vectors: it does
/// not go through this value.
[[nodiscard]] constexpr Fixed length_squared(Vec3 v) noexcept {
  return dot(v, v);
}

/// |v|: the correctly rounded square root of the exact sum of squares (error <= 0.5 ulp) for every
/// input; no intermediate overflow. Saturates to Fixed::max() only when |v| >= 2^31 (possible only
/// for components of magnitude above 2^30).
[[nodiscard]] Fixed length(Vec3 v) noexcept;
/// length(v) > limit, decided exactly from the sum of squares without taking the root: the same
/// answer as comparing length's rounded, saturated result, for every input, at the cost of four
/// multiplies (speed limits ask this of every body several times a step).
[[nodiscard]] constexpr bool length_exceeds(Vec3 v, Fixed limit) noexcept {
  // length's raw is the rounded root of n = X^2 + Y^2 + Z^2 (exact: < 3 * 2^126), saturated.
  const auto square = [](Fixed c) {
    const std::uint64_t m = detail::magnitude(c.raw());
    return wide::Default::mul(m, m);
  };
  return detail::root_exceeds(wide::add(wide::add(square(v.x), square(v.y)), square(v.z)),
                              limit.raw());
}

/// |a - b| with the difference taken exactly (65 bits), then as length(): correctly rounded,
/// saturating to Fixed::max() when the distance is 2^31 or more.
[[nodiscard]] Fixed distance(Vec3 a, Vec3 b) noexcept;

/// v / |v|. Each component is within 0.5 ulp + 2^-30 ulp of the exact v_i / |v| (the vector is
/// first scaled by a power of two so that |v| is known to 63 bits, then each component is divided
/// once and rounded to nearest), hence | |normalize(v)|^2 - 1 | < 1.74 * 2^-32. Every nonzero input
/// works, including single-ulp and saturated components; axis-aligned vectors give exact unit
/// vectors. The zero vector normalizes to the zero vector (see normalize_or for a fallback).
[[nodiscard]] Vec3 normalize(Vec3 v) noexcept;

/// normalize(v), or `fallback` (returned unchanged) when v is the zero vector.
[[nodiscard]] Vec3 normalize_or(Vec3 v, Vec3 fallback) noexcept;

}  // namespace detsim

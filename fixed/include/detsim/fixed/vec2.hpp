// detsim::Vec2: a 2D vector of Fixed.
//
// Componentwise operations (+, -, scalar * and /) behave exactly like the Fixed operators: each
// component is rounded to nearest (ties to even) and saturated on its own. Products of vectors
// (dot, cross, length_squared) are the exact sum of exact 128-bit products, rounded once (ties to
// even) and then saturated: no intermediate overflow, no second rounding. length, normalize and
// distance (defined in vector.cpp) use a correctly rounded integer square root of the exact sum of
// squares.
#pragma once

#include <detsim/fixed/exact_sum.hpp>
#include <detsim/fixed/fixed.hpp>

namespace detsim {

/// A 2D vector of Fixed. A plain aggregate: `Vec2{x, y}`; the default is the zero vector.
struct Vec2 {
  Fixed x;
  Fixed y;

  [[nodiscard]] static constexpr Vec2 zero() noexcept { return {}; }
  [[nodiscard]] static constexpr Vec2 unit_x() noexcept { return {Fixed::one(), {}}; }
  [[nodiscard]] static constexpr Vec2 unit_y() noexcept { return {{}, Fixed::one()}; }

  /// Bitwise (and so value) equality of both components.
  friend constexpr bool operator==(Vec2, Vec2) noexcept = default;

  constexpr Vec2& operator+=(Vec2 b) noexcept;
  constexpr Vec2& operator-=(Vec2 b) noexcept;
  constexpr Vec2& operator*=(Fixed s) noexcept;
  constexpr Vec2& operator/=(Fixed s) noexcept;
};

/// Componentwise sum, each component saturated like Fixed +.
[[nodiscard]] constexpr Vec2 operator+(Vec2 a, Vec2 b) noexcept {
  return {a.x + b.x, a.y + b.y};
}
/// Componentwise difference, each component saturated like Fixed -.
[[nodiscard]] constexpr Vec2 operator-(Vec2 a, Vec2 b) noexcept {
  return {a.x - b.x, a.y - b.y};
}
/// Componentwise negation; a Fixed::min() component becomes Fixed::max().
[[nodiscard]] constexpr Vec2 operator-(Vec2 a) noexcept {
  return {-a.x, -a.y};
}
/// Each component times s, rounded (ties to even) and saturated like Fixed *.
[[nodiscard]] constexpr Vec2 operator*(Vec2 a, Fixed s) noexcept {
  return {a.x * s, a.y * s};
}
[[nodiscard]] constexpr Vec2 operator*(Fixed s, Vec2 a) noexcept {
  return a * s;
}
/// Each component divided by s, rounded and saturated like Fixed /; dividing by zero gives max(),
/// min() or 0 per component by the sign of that component.
[[nodiscard]] constexpr Vec2 operator/(Vec2 a, Fixed s) noexcept {
  return {a.x / s, a.y / s};
}

constexpr Vec2& Vec2::operator+=(Vec2 b) noexcept {
  return *this = *this + b;
}
constexpr Vec2& Vec2::operator-=(Vec2 b) noexcept {
  return *this = *this - b;
}
constexpr Vec2& Vec2::operator*=(Fixed s) noexcept {
  return *this = *this * s;
}
constexpr Vec2& Vec2::operator/=(Fixed s) noexcept {
  return *this = *this / s;
}

/// a . b: the exact sum of the exact products, rounded once (ties to even), then saturated. No
/// intermediate overflow for any inputs.
[[nodiscard]] constexpr Fixed dot(Vec2 a, Vec2 b) noexcept {
  detail::ProductSum s;
  s.add_product(a.x.raw(), b.x.raw());
  s.add_product(a.y.raw(), b.y.raw());
  return s.to_fixed();
}

/// The scalar cross product a.x b.y - a.y b.x (the z component of the 3D cross product): exact,
/// then rounded once and saturated. cross(a, a) == 0 and cross(b, a) == -cross(a, b) exactly,
/// except where the result saturates: max() one way round is min() (not -max()) the other.
[[nodiscard]] constexpr Fixed cross(Vec2 a, Vec2 b) noexcept {
  detail::ProductSum s;
  s.add_product(a.x.raw(), b.y.raw());
  s.sub_product(a.y.raw(), b.x.raw());
  return s.to_fixed();
}

/// |v|^2, exact then rounded once; saturates to Fixed::max() when |v|^2 >= 2^31. Use length() for
/// large vectors: it does not go through this value.
[[nodiscard]] constexpr Fixed length_squared(Vec2 v) noexcept {
  return dot(v, v);
}

/// |v|: the correctly rounded square root of the exact sum of squares (error <= 0.5 ulp); no
/// intermediate overflow. Saturates to Fixed::max() only when |v| >= 2^31.
[[nodiscard]] Fixed length(Vec2 v) noexcept;

/// |a - b| with the difference taken exactly (65 bits), correctly rounded, saturating to
/// Fixed::max() when the distance is 2^31 or more.
[[nodiscard]] Fixed distance(Vec2 a, Vec2 b) noexcept;

/// v / |v|. Each component is within 0.5 ulp + 2^-30 ulp of the exact v_i / |v|, hence
/// | |normalize(v)|^2 - 1 | < 1.42 * 2^-32. Every nonzero input works, including single-ulp and
/// saturated components; axis-aligned vectors give exact unit vectors. The zero vector normalizes
/// to the zero vector (see normalize_or for a fallback).
[[nodiscard]] Vec2 normalize(Vec2 v) noexcept;

/// normalize(v), or `fallback` (returned unchanged) when v is the zero vector.
[[nodiscard]] Vec2 normalize_or(Vec2 v, Vec2 fallback) noexcept;

}  // namespace detsim

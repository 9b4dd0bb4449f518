// detsim::Quat: a quaternion of Fixed (orientations of rigid bodies).
//
// Convention: w + x i + y j + z k with the Hamilton product (i j = k), right-handed rotations, and
// rotate(q, v) = q v q* for a unit q. The Hamilton product, dot, length_squared and to_mat3 take
// exact sums of exact 128-bit products and round each result component once, to nearest with ties
// to even, saturating to the Fixed range; rotate and integrate round one intermediate vector the
// same way first (documented on each).
//
// Unit quaternions. normalize, from_axis_angle and integrate return quaternions with
// | |q|^2 - 1 | < 2^-31 + 2^-56 (about two ulps), whatever their input, so a quaternion that is
// renormalised every step never drifts further than that. The error bounds of rotate and to_mat3
// below are stated for such a q; write eps = |q|^2 - 1.
#pragma once

#include <detsim/fixed/exact_sum.hpp>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/mat3.hpp>
#include <detsim/fixed/vec3.hpp>

namespace detsim {

/// A quaternion w + x i + y j + z k. A plain aggregate: `Quat{w, x, y, z}`. The default is the
/// identity rotation (w = 1), not the zero quaternion.
struct Quat {
  Fixed w = Fixed::one();
  Fixed x;
  Fixed y;
  Fixed z;

  [[nodiscard]] static constexpr Quat identity() noexcept { return {}; }

  /// The vector part (x, y, z).
  [[nodiscard]] constexpr Vec3 vector() const noexcept { return {x, y, z}; }

  /// Bitwise (and so value) equality of all four components. q and -q are different values even
  /// though they are the same rotation.
  friend constexpr bool operator==(Quat, Quat) noexcept = default;
};

/// The Hamilton product a b (apply b, then a). Each component is the exact sum of four exact
/// products, rounded once and saturated.
[[nodiscard]] constexpr Quat operator*(Quat a, Quat b) noexcept {
  detail::ProductSum w;
  w.add_product(a.w.raw(), b.w.raw());
  w.sub_product(a.x.raw(), b.x.raw());
  w.sub_product(a.y.raw(), b.y.raw());
  w.sub_product(a.z.raw(), b.z.raw());
  detail::ProductSum x;
  x.add_product(a.w.raw(), b.x.raw());
  x.add_product(a.x.raw(), b.w.raw());
  x.add_product(a.y.raw(), b.z.raw());
  x.sub_product(a.z.raw(), b.y.raw());
  detail::ProductSum y;
  y.add_product(a.w.raw(), b.y.raw());
  y.sub_product(a.x.raw(), b.z.raw());
  y.add_product(a.y.raw(), b.w.raw());
  y.add_product(a.z.raw(), b.x.raw());
  detail::ProductSum z;
  z.add_product(a.w.raw(), b.z.raw());
  z.add_product(a.x.raw(), b.y.raw());
  z.sub_product(a.y.raw(), b.x.raw());
  z.add_product(a.z.raw(), b.w.raw());
  return {w.to_fixed(), x.to_fixed(), y.to_fixed(), z.to_fixed()};
}

/// (w, -x, -y, -z): the inverse rotation of a unit quaternion. Exact, except that a Fixed::min()
/// component becomes Fixed::max().
[[nodiscard]] constexpr Quat conjugate(Quat q) noexcept {
  return {q.w, -q.x, -q.y, -q.z};
}

/// The four-dimensional dot product, exact then rounded once and saturated.
[[nodiscard]] constexpr Fixed dot(Quat a, Quat b) noexcept {
  detail::ProductSum s;
  s.add_product(a.w.raw(), b.w.raw());
  s.add_product(a.x.raw(), b.x.raw());
  s.add_product(a.y.raw(), b.y.raw());
  s.add_product(a.z.raw(), b.z.raw());
  return s.to_fixed();
}

/// |q|^2, exact then rounded once; saturates to Fixed::max() when |q|^2 >= 2^31.
[[nodiscard]] constexpr Fixed length_squared(Quat q) noexcept {
  return dot(q, q);
}

/// q / |q|. Each component is within 0.5 ulp + 2^-28 ulp of the exact q_i / |q| (the quaternion is
/// first scaled by a power of two so that |q| is known to 63 bits, then divided once), hence
/// | |normalize(q)|^2 - 1 | < 2^-31 + 2^-56. Every nonzero input works; the zero quaternion
/// normalizes to the identity.
[[nodiscard]] Quat normalize(Quat q) noexcept;

/// v rotated by q, in the form t = 2 (u x v), v' = v + w t + u x t (u = q's vector part), which
/// equals q v q* exactly when |q| = 1. t is rounded once per component (the exact doubled
/// cross product); each component of v' is the exact v + w t + u x t rounded once and saturated.
/// Error: |v' - R v| <= 2.1 ulp + 2 |eps| |v| (Euclidean norm, R the rotation of q / |q|): 0.87 ulp
/// from the final rounding, 1.23 ulp from t's rounding carried through w t + u x t, and the
/// exact-arithmetic value being R v + eps (R v - v). The intermediate t saturates (and the result
/// is then meaningless) only when a component of 2 u x v leaves the Fixed range, which needs |v| >=
/// 2^30 for a unit q; below that, only results beyond the Fixed range saturate.
[[nodiscard]] constexpr Vec3 rotate(Quat q, Vec3 v) noexcept {
  const auto doubled_cross = [](Fixed p, Fixed r, Fixed s, Fixed t) {
    detail::ProductSum sum;  // 2 (p r - s t): rounding at 31 bits instead of 32 doubles exactly
    sum.add_product(p.raw(), r.raw());
    sum.sub_product(s.raw(), t.raw());
    return sum.round_to_raw(Fixed::fraction_bits - 1);
  };
  const std::int64_t tx = doubled_cross(q.y, v.z, q.z, v.y);
  const std::int64_t ty = doubled_cross(q.z, v.x, q.x, v.z);
  const std::int64_t tz = doubled_cross(q.x, v.y, q.y, v.x);
  // v + w t + u x t, with v scaled to Q64.64 so the whole component is one exact sum.
  const auto component = [&q](Fixed vi, std::int64_t ti, Fixed p, std::int64_t r, Fixed s,
                              std::int64_t t) {
    detail::ProductSum sum;
    sum.add_scaled(vi.raw(), Fixed::fraction_bits);
    sum.add_product(q.w.raw(), ti);
    sum.add_product(p.raw(), r);
    sum.sub_product(s.raw(), t);
    return sum.to_fixed();
  };
  return {component(v.x, tx, q.y, tz, q.z, ty), component(v.y, ty, q.z, tx, q.x, tz),
          component(v.z, tz, q.x, ty, q.y, tx)};
}

/// The rotation matrix of q: the entries 1 - 2 (y^2 + z^2), 2 (x y - w z), ... each computed
/// exactly and rounded once (error <= 0.5 ulp per entry). It is the matrix of the map that rotate
/// applies, so to_mat3(q) * v agrees with rotate(q, v) up to rounding for every q. In exact
/// arithmetic it equals R + eps (R - I) (R the rotation of q / |q|), so every entry of to_mat3(q)
/// to_mat3(q)^T differs from the identity by at most 4 |eps| + 1.74 ulp (about 10 ulp for a
/// normalised q) before that product's own rounding. An entry saturates only if it leaves the Fixed
/// range (needs |q|^2 >= 2^30).
[[nodiscard]] constexpr Mat3 to_mat3(Quat q) noexcept {
  const std::int64_t w = q.w.raw();
  const std::int64_t x = q.x.raw();
  const std::int64_t y = q.y.raw();
  const std::int64_t z = q.z.raw();
  // Each entry is 2 * (exact sum), rounded by shifting 31 bits instead of 32. The diagonal is
  // 2 (1/2 - a^2 - b^2), with 1/2 = 2^63 in Q64.64.
  const auto diagonal = [](std::int64_t a, std::int64_t b) {
    detail::ProductSum s;
    s.add(false, wide::U128{0, std::uint64_t{1} << 63});
    s.sub_product(a, a);
    s.sub_product(b, b);
    return Fixed::from_raw(s.round_to_raw(Fixed::fraction_bits - 1));
  };
  const auto off_diagonal = [](std::int64_t a, std::int64_t b, bool minus, std::int64_t c,
                               std::int64_t d) {
    detail::ProductSum s;  // 2 (a b +- c d)
    s.add_product(a, b);
    if (minus) {
      s.sub_product(c, d);
    } else {
      s.add_product(c, d);
    }
    return Fixed::from_raw(s.round_to_raw(Fixed::fraction_bits - 1));
  };
  return {{Vec3{diagonal(y, z), off_diagonal(x, y, true, w, z), off_diagonal(x, z, false, w, y)},
           Vec3{off_diagonal(x, y, false, w, z), diagonal(x, z), off_diagonal(y, z, true, w, x)},
           Vec3{off_diagonal(x, z, true, w, y), off_diagonal(y, z, false, w, x), diagonal(x, y)}}};
}

/// The unit quaternion of a rotation by `angle` radians (right-handed) about `axis`. The axis is
/// normalised first (its length does not matter); a zero axis gives the identity. The half angle is
/// angle / 2 rounded to nearest; its sine and cosine come from sincos, and the result is
/// renormalised, so | |q|^2 - 1 | < 2^-31 + 2^-56. The result is within 7 ulp (Euclidean norm) of
/// the exact quaternion for the rounded half angle: sincos (< 1 ulp each), the unit axis (0.87 ulp)
/// and the products (0.87 ulp) put the unnormalised value within 2.92 ulp, projecting onto the unit
/// sphere at most doubles that, and the normalisation rounds by 1 ulp more.
[[nodiscard]] Quat from_axis_angle(Vec3 axis, Fixed angle) noexcept;

/// One explicit step of the orientation equation dq/dt = (1/2) (0, omega) q over dt seconds:
/// q' = normalize(q + (dt / 2) (0, omega) q), omega the angular velocity in world space (radians
/// per second). (dt / 2) omega is rounded once per component and q + ... once per component
/// before the renormalisation, so the result is a unit quaternion within the normalize bound,
/// | |q'|^2 - 1 | < 2^-31 + 2^-56, after any number of steps. For a constant omega, a step rotates
/// by 2 atan(|omega| dt / 2) about omega (slightly less than |omega| dt: the usual first-order
/// error, 0.2% per step at |omega| dt = 0.16).
[[nodiscard]] Quat integrate(Quat q, Vec3 angular_velocity, Fixed dt) noexcept;

}  // namespace detsim

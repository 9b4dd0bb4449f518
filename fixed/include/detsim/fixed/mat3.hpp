// detsim::Mat3: a row-major 3x3 matrix of Fixed (rotations, inertia tensors and their inverses).
//
// Every entry of a product (matrix-matrix, matrix-vector), the determinant and every entry of
// rotate_inertia is the exact sum of exact products, rounded once to nearest (ties to even) and
// then saturated: no intermediate overflow, no second rounding. inverse() divides exact cofactors
// by the exact determinant with a relative error below 2^-61 before its one rounding. A rotation
// matrix is built from a quaternion with to_mat3 in <detsim/fixed/quat.hpp>.
#pragma once

#include <array>
#include <cstddef>

#include <detsim/fixed/exact_sum.hpp>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/vec3.hpp>

namespace detsim {

/// A 3x3 matrix stored as three rows. A plain aggregate: `Mat3{{row0, row1, row2}}`; the default is
/// the zero matrix.
struct Mat3 {
  std::array<Vec3, 3> rows;

  [[nodiscard]] static constexpr Mat3 zero() noexcept { return {}; }
  [[nodiscard]] static constexpr Mat3 identity() noexcept {
    return {{Vec3::unit_x(), Vec3::unit_y(), Vec3::unit_z()}};
  }
  [[nodiscard]] static constexpr Mat3 diagonal(Fixed d0, Fixed d1, Fixed d2) noexcept {
    return {{Vec3{d0, {}, {}}, Vec3{{}, d1, {}}, Vec3{{}, {}, d2}}};
  }

  /// Column j (0, 1 or 2; any other j reads column 2).
  [[nodiscard]] constexpr Vec3 column(std::size_t j) const noexcept {
    const auto pick = [j](Vec3 r) { return j == 0 ? r.x : (j == 1 ? r.y : r.z); };
    return {pick(rows[0]), pick(rows[1]), pick(rows[2])};
  }

  /// Bitwise (and so value) equality of all nine entries.
  friend constexpr bool operator==(const Mat3&, const Mat3&) noexcept = default;
};

/// Entrywise sum, saturated like Fixed +.
[[nodiscard]] constexpr Mat3 operator+(const Mat3& a, const Mat3& b) noexcept {
  return {{a.rows[0] + b.rows[0], a.rows[1] + b.rows[1], a.rows[2] + b.rows[2]}};
}
/// Entrywise difference, saturated like Fixed -.
[[nodiscard]] constexpr Mat3 operator-(const Mat3& a, const Mat3& b) noexcept {
  return {{a.rows[0] - b.rows[0], a.rows[1] - b.rows[1], a.rows[2] - b.rows[2]}};
}
/// Every entry times s, rounded and saturated like Fixed *.
[[nodiscard]] constexpr Mat3 operator*(const Mat3& a, Fixed s) noexcept {
  return {{a.rows[0] * s, a.rows[1] * s, a.rows[2] * s}};
}
[[nodiscard]] constexpr Mat3 operator*(Fixed s, const Mat3& a) noexcept {
  return a * s;
}

[[nodiscard]] constexpr Mat3 transpose(const Mat3& m) noexcept {
  return {{m.column(0), m.column(1), m.column(2)}};
}

/// m v: each component is dot(row, v), exact then rounded once and saturated.
[[nodiscard]] constexpr Vec3 operator*(const Mat3& m, Vec3 v) noexcept {
  return {dot(m.rows[0], v), dot(m.rows[1], v), dot(m.rows[2], v)};
}

/// a b: each entry is the exact sum of three exact products, rounded once and saturated.
[[nodiscard]] constexpr Mat3 operator*(const Mat3& a, const Mat3& b) noexcept {
  const Vec3 c0 = b.column(0);
  const Vec3 c1 = b.column(1);
  const Vec3 c2 = b.column(2);
  const auto row = [&](Vec3 r) { return Vec3{dot(r, c0), dot(r, c1), dot(r, c2)}; };
  return {{row(a.rows[0]), row(a.rows[1]), row(a.rows[2])}};
}

/// det(m) = row0 . (row1 x row2): the exact sum of the six products of three entries (up to 193
/// bits), rounded once (ties to even) and saturated to the Fixed range.
[[nodiscard]] constexpr Fixed determinant(const Mat3& m) noexcept {
  const Vec3 a = m.rows[0];
  const Vec3 b = m.rows[1];
  const Vec3 c = m.rows[2];
  detail::TripleProductSum s;
  s.add_product(a.x.raw(), b.y.raw(), c.z.raw());
  s.add_product(a.y.raw(), b.z.raw(), c.x.raw());
  s.add_product(a.z.raw(), b.x.raw(), c.y.raw());
  s.sub_product(a.x.raw(), b.z.raw(), c.y.raw());
  s.sub_product(a.y.raw(), b.x.raw(), c.z.raw());
  s.sub_product(a.z.raw(), b.y.raw(), c.x.raw());
  return Fixed::from_raw(s.round_to_raw(2 * Fixed::fraction_bits));
}

/// Writes m^-1 to `out` and returns true when m is invertible and every entry of the inverse fits
/// in Fixed. Otherwise (det(m) == 0 exactly, or some entry of the inverse would saturate) returns
/// false and leaves `out` unchanged. Each entry is the exact cofactor divided by the exact
/// determinant: within 0.5 ulp + 2^-61 |entry| of the exact inverse entry.
[[nodiscard]] bool try_inverse(const Mat3& m, Mat3& out) noexcept;

/// m^-1 as try_inverse computes it, or the zero matrix when m is singular or its inverse does not
/// fit in Fixed (see try_inverse).
[[nodiscard]] Mat3 inverse(const Mat3& m) noexcept;

/// rotation * inertia * transpose(rotation): a body-space inertia tensor (or inverse inertia
/// tensor) in world space. `inertia` is taken as symmetric: only its upper triangle is read. Each
/// entry of the upper triangle is the exact sum of products of three entries, rounded once (error
/// <= 0.5 ulp) and saturated; the lower triangle is a copy, so the result is exactly symmetric.
[[nodiscard]] Mat3 rotate_inertia(const Mat3& rotation, const Mat3& inertia) noexcept;

}  // namespace detsim

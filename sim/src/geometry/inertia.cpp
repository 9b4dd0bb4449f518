// Principal frames (cyclic Jacobi) and the parallel-axis shift; see inertia.hpp.
//
// Why our own eigen-solver: a library's (Eigen, LAPACK) runs in floating point, whose results
// differ between compilers and targets; this one is Fixed arithmetic only, with a fixed order of
// rotations and a capped sweep count, so the same tensor gives the same frame everywhere.
#include "inertia.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>

#include <detsim/fixed/exact_sum.hpp>
#include <detsim/fixed/math.hpp>

namespace detsim::sim_detail {

namespace inertia_detail {

using Matrix = std::array<std::array<Fixed, 3>, 3>;

/// a b + c d, summed exactly and rounded once.
Fixed sum_of_products(Fixed a, Fixed b, Fixed c, Fixed d) noexcept {
  detail::ProductSum s;
  s.add_product(a.raw(), b.raw());
  s.add_product(c.raw(), d.raw());
  return s.to_fixed();
}

std::uint64_t magnitude(Fixed x) noexcept {
  const auto r = static_cast<std::uint64_t>(x.raw());
  return x.raw() < 0 ? 0U - r : r;
}

/// One Jacobi rotation in the (p, q) plane that zeroes a[p][q] (Numerical Recipes, "jacobi":
/// theta = (a_qq - a_pp) / (2 a_pq), t = sgn(theta) / (|theta| + sqrt(theta^2 + 1)) is the
/// tangent of the smaller rotation angle, c = 1 / sqrt(t^2 + 1), s = t c). v accumulates the
/// rotations: its columns become the eigenvectors.
void rotate(Matrix& a, Matrix& v, std::size_t p, std::size_t q) noexcept {
  const Fixed apq = a[p][q];
  if (apq == Fixed::zero()) return;
  const Fixed theta = (a[q][q] - a[p][p]) / (apq + apq);
  Fixed t;
  const Fixed big = Fixed::from_int(1 << 15);
  if (abs(theta) > big) {
    // theta^2 would leave the range; 1 / (2 theta) is t to a relative 1 / (4 theta^2) < 2^-32.
    t = Fixed::one() / (theta + theta);
  } else {
    t = Fixed::one() / (abs(theta) + sqrt(theta * theta + Fixed::one()));
    if (theta < Fixed::zero()) t = -t;
  }
  if (t == Fixed::zero()) {
    // The rotation is below the resolution: a_pq is negligible against a_qq - a_pp.
    a[p][q] = a[q][p] = Fixed::zero();
    return;
  }
  const Fixed c = rsqrt(t * t + Fixed::one());
  const Fixed s = t * c;
  const Fixed tapq = t * apq;
  a[p][p] = a[p][p] - tapq;
  a[q][q] = a[q][q] + tapq;
  a[p][q] = a[q][p] = Fixed::zero();
  const std::size_t r = 3 - p - q;
  const Fixed arp = a[r][p];
  const Fixed arq = a[r][q];
  a[r][p] = a[p][r] = sum_of_products(c, arp, -s, arq);
  a[r][q] = a[q][r] = sum_of_products(s, arp, c, arq);
  for (std::size_t i = 0; i < 3; ++i) {
    const Fixed vip = v[i][p];
    const Fixed viq = v[i][q];
    v[i][p] = sum_of_products(c, vip, -s, viq);
    v[i][q] = sum_of_products(s, vip, c, viq);
  }
}

}  // namespace inertia_detail

PrincipalFrame principal_frame(const Mat3& tensor) noexcept {
  using namespace inertia_detail;
  const Fixed a00 = tensor.rows[0].x;
  const Fixed a11 = tensor.rows[1].y;
  const Fixed a22 = tensor.rows[2].z;
  const Fixed a01 = tensor.rows[0].y;
  const Fixed a02 = tensor.rows[0].z;
  const Fixed a12 = tensor.rows[1].z;
  // Already diagonal: its own frame, exactly (the primitive shapes rely on the identity).
  if (a01 == Fixed::zero() && a02 == Fixed::zero() && a12 == Fixed::zero())
    return {{a00, a11, a22}, Quat::identity()};

  // Scale by 2^shift so that the largest entry lies in [1, 2): the rotations then work with the
  // full 32 fraction bits whatever the tensor's units (a millimetre part's m^2 moments are ~1e-7),
  // and no product of entries can leave the range. Powers of two scale exactly upwards.
  std::uint64_t largest = 0;
  for (const Fixed x : {a00, a11, a22, a01, a02, a12})
    largest = std::max(largest, magnitude(x));
  const int bits = 64 - std::countl_zero(largest);  // largest in [2^(bits-1), 2^bits)
  const int shift = Fixed::fraction_bits + 1 - bits;
  Matrix a{};
  a[0] = {a00 << shift, a01 << shift, a02 << shift};
  a[1] = {a01 << shift, a11 << shift, a12 << shift};
  a[2] = {a02 << shift, a12 << shift, a22 << shift};
  Matrix v{};
  v[0][0] = v[1][1] = v[2][2] = Fixed::one();

  // Cyclic sweeps in the fixed order (0,1), (0,2), (1,2) until the off-diagonal is exactly zero.
  for (int sweep = 0; sweep < max_jacobi_sweeps; ++sweep) {
    if (a[0][1] == Fixed::zero() && a[0][2] == Fixed::zero() && a[1][2] == Fixed::zero()) break;
    rotate(a, v, 0, 1);
    rotate(a, v, 0, 2);
    rotate(a, v, 1, 2);
  }
  const Vec3 moments{a[0][0] >> shift, a[1][1] >> shift, a[2][2] >> shift};
  const Mat3 rotation{{Vec3{v[0][0], v[0][1], v[0][2]}, Vec3{v[1][0], v[1][1], v[1][2]},
                       Vec3{v[2][0], v[2][1], v[2][2]}}};
  return {moments, quat_from_rotation(rotation)};
}

Mat3 shift_inertia(const Mat3& about_centroid_per_mass, Vec3 d) noexcept {
  // Parallel axes: I_P = I_C + |d|^2 E - d d^T, per unit mass. Each entry is summed exactly
  // (ProductSum) and rounded once.
  Mat3 out = about_centroid_per_mass;
  const std::array<Fixed, 3> c{d.x, d.y, d.z};
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = 0; j < 3; ++j) {
      detail::ProductSum s;
      if (i == j) {
        for (std::size_t k = 0; k < 3; ++k) {
          if (k != i) s.add_product(c[k].raw(), c[k].raw());
        }
      } else {
        s.sub_product(c[i].raw(), c[j].raw());
      }
      Vec3& row = out.rows[i];
      Fixed& entry = j == 0 ? row.x : (j == 1 ? row.y : row.z);
      entry = s.to_fixed_plus(entry.raw());
    }
  }
  return out;
}

Quat quat_from_rotation(const Mat3& m) noexcept {
  const Fixed m00 = m.rows[0].x;
  const Fixed m01 = m.rows[0].y;
  const Fixed m02 = m.rows[0].z;
  const Fixed m10 = m.rows[1].x;
  const Fixed m11 = m.rows[1].y;
  const Fixed m12 = m.rows[1].z;
  const Fixed m20 = m.rows[2].x;
  const Fixed m21 = m.rows[2].y;
  const Fixed m22 = m.rows[2].z;
  const Fixed one = Fixed::one();
  const Fixed four = Fixed::from_int(4);
  const Fixed trace = m00 + m11 + m22;
  Quat q;
  // The largest of 4w^2 = 1 + trace, 4x^2 = 1 + m00 - m11 - m22, ... is at least 1, so its root
  // (>= 1/2) divides the others well. Ties go to the first in this order.
  if (trace >= m00 && trace >= m11 && trace >= m22) {
    const Fixed w = sqrt(one + trace) / Fixed::from_int(2);
    q = {w, (m21 - m12) / (four * w), (m02 - m20) / (four * w), (m10 - m01) / (four * w)};
  } else if (m00 >= m11 && m00 >= m22) {
    const Fixed x = sqrt(one + m00 - m11 - m22) / Fixed::from_int(2);
    q = {(m21 - m12) / (four * x), x, (m01 + m10) / (four * x), (m02 + m20) / (four * x)};
  } else if (m11 >= m22) {
    const Fixed y = sqrt(one - m00 + m11 - m22) / Fixed::from_int(2);
    q = {(m02 - m20) / (four * y), (m01 + m10) / (four * y), y, (m12 + m21) / (four * y)};
  } else {
    const Fixed z = sqrt(one - m00 - m11 + m22) / Fixed::from_int(2);
    q = {(m10 - m01) / (four * z), (m02 + m20) / (four * z), (m12 + m21) / (four * z), z};
  }
  if (q.w < Fixed::zero()) q = {-q.w, -q.x, -q.y, -q.z};
  if (q == Quat::identity()) return q;
  return normalize(q);
}

}  // namespace detsim::sim_detail

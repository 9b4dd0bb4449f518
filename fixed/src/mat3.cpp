// Matrix inverse and inertia-tensor rotation: the Mat3 operations too long to inline.
#include <array>
#include <bit>
#include <cstdint>

#include <detsim/fixed/exact_sum.hpp>
#include <detsim/fixed/mat3.hpp>

namespace detsim {
namespace {

using Raws = std::array<std::array<std::int64_t, 3>, 3>;

Raws raws_of(const Mat3& m) noexcept {
  Raws r{};
  for (std::size_t i = 0; i < 3; ++i)
    r[i] = {m.rows[i].x.raw(), m.rows[i].y.raw(), m.rows[i].z.raw()};
  return r;
}

/// Index of the highest set bit of a nonzero little-endian multi-limb value.
template <std::size_t N>
unsigned top_bit(const std::array<std::uint64_t, N>& v) noexcept {
  for (std::size_t i = N; i-- > 0;) {
    if (v[i] != 0)
      return static_cast<unsigned>(64 * i) + 63U - static_cast<unsigned>(std::countl_zero(v[i]));
  }
  return 0;
}

/// The 64 bits of v starting at bit `low` (bits beyond the top read as zero).
template <std::size_t N>
std::uint64_t bits_at(const std::array<std::uint64_t, N>& v, unsigned low) noexcept {
  const std::size_t word = low / 64;
  const unsigned bit = low % 64;
  std::uint64_t r = v[word] >> bit;
  if (bit != 0 && word + 1 < N) r |= v[word + 1] << (64 - bit);
  return r;
}

/// The top 64 bits of a nonzero v (its highest set bit moved to bit 63, truncated) and the
/// exponent e with v ~ normalized * 2^e, the truncation losing less than 2^-63 relative.
template <std::size_t N>
std::uint64_t normalized(const std::array<std::uint64_t, N>& v, int& exponent) noexcept {
  const unsigned top = top_bit(v);
  exponent = static_cast<int>(top) - 63;
  if (top >= 63) return bits_at(v, top - 63);
  return v[0] << (63 - top);
}

/// Raw bits of (cofactor / 2^64) / (det / 2^96), i.e. cofactor * 2^64 / det, for the magnitudes of
/// an exact cofactor (Q64.64) and an exact nonzero determinant (Q96.96). Returns false when the
/// magnitude reaches 2^63 (beyond Fixed; -2^31 is treated as overflow too).
///
/// Both operands are cut to their top 64 bits (each a relative error below 2^-63), divided once by
/// the 128/64 division, and the quotient is rounded to nearest (ties to even) with the division's
/// remainder as sticky bit: the result is within 0.5 ulp + 2^-61 |result| of the exact quotient.
bool quotient_raw(bool negative, wide::U128 cofactor, const std::array<std::uint64_t, 4>& det,
                  std::int64_t& out) noexcept {
  if (cofactor.hi == 0 && cofactor.lo == 0) {
    out = 0;
    return true;
  }
  int cofactor_exponent = 0;
  int det_exponent = 0;
  const std::uint64_t c = normalized(std::array{cofactor.lo, cofactor.hi}, cofactor_exponent);
  const std::uint64_t d = normalized(det, det_exponent);
  // Both have bit 63 set, so c / d lies in (1/2, 2): scale the numerator so the quotient q lies in
  // [2^63, 2^64), and the result is q * 2^exponent.
  const bool c_below_d = c < d;
  const wide::U128 numerator = c_below_d ? wide::U128{c, 0} : wide::U128{c >> 1, c << 63};
  const wide::DivResult qr = wide::Default::div(numerator, d);
  const int exponent = cofactor_exponent - det_exponent + (c_below_d ? 0 : 1);
  if (exponent >= 0) return false;  // |result| >= 2^63
  const auto shift = static_cast<unsigned>(-exponent);
  std::uint64_t magnitude = 0;
  if (shift == 64) {
    // q / 2^64 lies in [1/2, 1): 1 unless it is exactly the tie 1/2 (which goes to the even 0).
    magnitude = (qr.quotient > (std::uint64_t{1} << 63) || qr.remainder != 0) ? 1 : 0;
  } else if (shift < 64) {
    // One extra low bit carries "the remainder was nonzero", so ties are recognised exactly.
    const wide::U128 q_sticky{qr.quotient >> 63,
                              (qr.quotient << 1) | (qr.remainder != 0 ? 1U : 0U)};
    magnitude = detail::round_shift_right(q_sticky, shift + 1);
  }
  if (magnitude >= (std::uint64_t{1} << 63)) return false;
  out = negative ? -static_cast<std::int64_t>(magnitude) : static_cast<std::int64_t>(magnitude);
  return true;
}

}  // namespace

bool try_inverse(const Mat3& m, Mat3& out) noexcept {
  const Raws a = raws_of(m);
  // The inverse is adj(m) / det(m), and the columns of adj(m) are row1 x row2, row2 x row0 and
  // row0 x row1. Each cofactor is exact (at most 2^127 in magnitude, Q64.64); the determinant is
  // row0 . (row1 x row2), exact in Q96.96.
  std::array<std::array<detail::ProductSum, 3>, 3> cofactor{};  // cofactor[j][i]: column j, entry i
  for (std::size_t j = 0; j < 3; ++j) {
    const auto& p = a[(j + 1) % 3];
    const auto& q = a[(j + 2) % 3];
    for (std::size_t i = 0; i < 3; ++i) {
      const std::size_t u = (i + 1) % 3;
      const std::size_t v = (i + 2) % 3;
      cofactor[j][i].add_product(p[u], q[v]);
      cofactor[j][i].sub_product(p[v], q[u]);
    }
  }
  detail::TripleProductSum det;
  for (std::size_t i = 0; i < 3; ++i) {
    det.add_product(cofactor[0][i].negative(), cofactor[0][i].magnitude_128(), a[0][i]);
  }
  if (det.is_zero()) return false;
  const auto det_magnitude = det.magnitude_words();
  Raws inv{};
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = 0; j < 3; ++j) {
      const detail::ProductSum& c = cofactor[j][i];
      if (!quotient_raw(c.negative() != det.negative(), c.magnitude_128(), det_magnitude,
                        inv[i][j])) {
        return false;
      }
    }
  }
  for (std::size_t i = 0; i < 3; ++i) {
    out.rows[i] = {Fixed::from_raw(inv[i][0]), Fixed::from_raw(inv[i][1]),
                   Fixed::from_raw(inv[i][2])};
  }
  return true;
}

Mat3 inverse(const Mat3& m) noexcept {
  Mat3 result;
  return try_inverse(m, result) ? result : Mat3::zero();
}

Mat3 rotate_inertia(const Mat3& rotation, const Mat3& inertia) noexcept {
  const Raws r = raws_of(rotation);
  const Raws t = raws_of(inertia);
  // (R I R^T)_ij = sum_kl R_ik I_kl R_jl. With I symmetric, the terms k != l pair up:
  // sum_k I_kk R_ik R_jk + sum_{k<l} I_kl (R_ik R_jl + R_il R_jk). Each pair is exact in Q64.64
  // (at most 2^127), each term at most 2^190 in Q96.96, and the six terms sum below 2^193.
  // Zero pairs are skipped (a diagonal tensor has none), and an isotropic tensor d 1 (a sphere's,
  // a cube's) takes its common factor out: d sum_k R_ik R_jk, one product by d instead of three.
  // Either way the exact sum is the same, and so is its one rounding.
  const bool isotropic =
      t[0][1] == 0 && t[0][2] == 0 && t[1][2] == 0 && t[0][0] == t[1][1] && t[1][1] == t[2][2];
  Raws w{};
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = i; j < 3; ++j) {
      detail::TripleProductSum s;
      if (isotropic) {
        detail::ProductSum rr;  // |sum| < 3 * 2^126: fits in 128 bits
        for (std::size_t k = 0; k < 3; ++k)
          rr.add_product(r[i][k], r[j][k]);
        s.add_product(rr.negative(), rr.magnitude_128(), t[0][0]);
      } else {
        for (std::size_t k = 0; k < 3; ++k) {
          s.add_product(r[i][k], r[j][k], t[k][k]);
          for (std::size_t l = k + 1; l < 3; ++l) {
            if (t[k][l] == 0) continue;
            detail::ProductSum pair;
            pair.add_product(r[i][k], r[j][l]);
            pair.add_product(r[i][l], r[j][k]);
            s.add_product(pair.negative(), pair.magnitude_128(), t[k][l]);
          }
        }
      }
      w[i][j] = s.round_to_raw(2 * Fixed::fraction_bits);
      w[j][i] = w[i][j];
    }
  }
  Mat3 result;
  for (std::size_t i = 0; i < 3; ++i) {
    result.rows[i] = {Fixed::from_raw(w[i][0]), Fixed::from_raw(w[i][1]), Fixed::from_raw(w[i][2])};
  }
  return result;
}

}  // namespace detsim

// Scaling a vector of raw Q32.32 components to unit length: shared by Vec2, Vec3 and Quat.
// Internal to the fixed module; not installed.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/wide.hpp>

#include "isqrt.hpp"
#include "leading_zeros.hpp"

namespace detsim::detail {

/// The sign of v as a mask: all ones when v < 0, else 0.
constexpr std::uint64_t sign_mask(std::int64_t v) noexcept {
  return static_cast<std::uint64_t>(v >> 63);
}

/// m_i 2^32 / length rounded to nearest, ties to even: one 128/64 division. m_i <= 2^63 and
/// length >= 2^62, so the numerator's high half m_i / 2^32 <= 2^31 is below length and the quotient
/// fits; m_i <= sqrt(S) <= length + 1/2 makes it at most 2^32 (a unit component) after rounding.
inline std::uint64_t rounded_quotient(std::uint64_t m_i, std::uint64_t length) noexcept {
  const wide::DivResult qr = wide::Default::div(wide::U128{m_i >> 32, m_i << 32}, length);
  const bool over_half = (qr.remainder >> 63) != 0 || (qr.remainder << 1) > length;
  const bool tie = (qr.remainder >> 63) == 0 && (qr.remainder << 1) == length;
  return qr.quotient + ((over_half || (tie && (qr.quotient & 1U) != 0)) ? 1U : 0U);
}

/// Replaces the raw components c by those of c / |c| and returns true; returns false and leaves c
/// unchanged when c is the zero vector.
///
/// Precision: normalising is invariant under scaling, so the magnitudes are first shifted left by a
/// common amount that puts the largest in [2^62, 2^63]. The sum of squares S then lies in
/// [2^124, N 2^126] (below 2^128 for N <= 3) and L = round(sqrt(S)) has |L - sqrt(S)| <= 0.5 with
/// L >= 2^62, a relative error of at most 2^-63. Each component is c_i 2^32 / L rounded to
/// nearest (ties to even): the exact quotient with L in place of sqrt(S) is off by at most
/// 2^32 2^-63 = 2^-31 ulp, and the rounding adds at most 0.5 ulp.
///
/// Speed: that result is computed without L and without dividing, except near a halfway point.
/// reciprocal_root gives y with y 2^(k - 125) = (1 + b) / sqrt(S), |b| < 2^-41.49. Then
/// m_i y 2^(k - 93) = Q_i (1 + b)(1 + l), where Q_i = m_i 2^32 / L is the quotient to be rounded
/// and 1 + l = L / sqrt(S), |l| <= 2^-63; as m_i <= sqrt(S), Q_i <= 2^32 (1 + 2^-63), so that
/// product is within 2^-9.48 of Q_i. The high half P_i of m_i y holds it with g = 29 - k fraction
/// bits, truncated by less than 2^-28: |P_i / 2^g - Q_i| < 2^-9.47. So round(P_i / 2^g) (half up)
/// is the correctly rounded Q_i unless the fraction of P_i / 2^g is within 2^-9 of 1/2 (which
/// includes every tie). Only then (about one component in 2^8; in the 1000-box pile under 1%
/// of normalisations) are L and the divisions computed, as defined above.
template <std::size_t N>
bool normalize_raw(std::array<std::int64_t, N>& c) noexcept {
  static_assert(N >= 2 && N <= 4);
  std::array<std::uint64_t, N> m{};
  std::uint64_t largest = 0;
  for (std::size_t i = 0; i < N; ++i) {
    // |c_i| and, at the end, the sign of c_i by masks: magnitude() and signed_saturate() compile
    // to branches on the sign here, which the random signs of directions defeat.
    m[i] = (static_cast<std::uint64_t>(c[i]) ^ sign_mask(c[i])) - sign_mask(c[i]);
    largest = m[i] > largest ? m[i] : largest;
  }
  if (largest == 0) return false;
  constexpr std::uint64_t top = std::uint64_t{1} << 63;
  if (N == 4 && largest == top) {
    // Four squares of 2^63 would reach 2^128. Halve every magnitude, rounding to nearest (ties to
    // even): a change of at most 2^-63 relative to the largest, 2^-30 ulp in the result.
    for (std::uint64_t& mi : m) {
      const std::uint64_t half = mi >> 1;
      mi = half + (mi & half & 1U);
    }
    largest = top >> 1;
  }
  const int leading = leading_zeros(largest);
  const auto shift = static_cast<unsigned>(leading > 0 ? leading - 1 : 0);
  wide::U128 sum_of_squares{};
  for (std::uint64_t& mi : m) {
    mi <<= shift;
    sum_of_squares = wide::add(sum_of_squares, wide::Default::mul(mi, mi));
  }
  const ReciprocalRoot estimate = reciprocal_root(sum_of_squares);  // k = 0 or 1: S >= 2^124
  const unsigned g = 29 - estimate.shift;
  const std::uint64_t half = std::uint64_t{1} << (g - 1);
  const std::uint64_t margin = std::uint64_t{1} << (g - 9);
  std::array<std::uint64_t, N> q{};
  bool near_halfway = false;
  for (std::size_t i = 0; i < N; ++i) {
    const std::uint64_t p = wide::Default::mul(m[i], estimate.reciprocal).hi;  // < 2^62
    q[i] = (p + half) >> g;
    // |fraction - 1/2| < 2^-9 as one unsigned comparison (wraps when the fraction is below).
    near_halfway |= (p & ((half << 1) - 1)) - (half - margin) < 2 * margin;
  }
  if (near_halfway) {
    const std::uint64_t length = isqrt_round(sum_of_squares);  // >= 2^62
    for (std::size_t i = 0; i < N; ++i) {
      q[i] = rounded_quotient(m[i], length);
    }
  }
  for (std::size_t i = 0; i < N; ++i) {
    c[i] = static_cast<std::int64_t>((q[i] ^ sign_mask(c[i])) - sign_mask(c[i]));  // q_i <= 2^32
  }
  return true;
}

}  // namespace detsim::detail

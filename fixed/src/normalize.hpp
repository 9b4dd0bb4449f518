// Scaling a vector of raw Q32.32 components to unit length: shared by Vec2, Vec3 and Quat.
// Internal to the fixed module; not installed.
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/wide.hpp>

#include "isqrt.hpp"

namespace detsim::detail {

/// Replaces the raw components c by those of c / |c| and returns true; returns false and leaves c
/// unchanged when c is the zero vector.
///
/// Precision: normalising is invariant under scaling, so the magnitudes are first shifted left by a
/// common amount that puts the largest in [2^62, 2^63]. The sum of squares S then lies in
/// [2^124, N 2^126] (below 2^128 for N <= 3) and L = round(sqrt(S)) has |L - sqrt(S)| <= 0.5 with
/// L >= 2^62, a relative error of at most 2^-63. Each component is one rounded 128/64 division,
/// c_i 2^32 / L: the exact quotient with L in place of sqrt(S) is off by at most 2^32 2^-63 =
/// 2^-31 ulp, and the rounding adds at most 0.5 ulp.
template <std::size_t N>
bool normalize_raw(std::array<std::int64_t, N>& c) noexcept {
  static_assert(N >= 2 && N <= 4);
  std::array<std::uint64_t, N> m{};
  std::uint64_t largest = 0;
  for (std::size_t i = 0; i < N; ++i) {
    m[i] = magnitude(c[i]);
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
  const int leading = std::countl_zero(largest);
  const auto shift = static_cast<unsigned>(leading > 0 ? leading - 1 : 0);
  wide::U128 sum_of_squares{};
  for (std::uint64_t& mi : m) {
    mi <<= shift;
    sum_of_squares = wide::add(sum_of_squares, wide::Default::mul(mi, mi));
  }
  const std::uint64_t length = isqrt_round(sum_of_squares);  // >= 2^62
  for (std::size_t i = 0; i < N; ++i) {
    // m_i 2^32 / length: the numerator's high half m_i / 2^32 < 2^31 is below length, so the
    // quotient fits, and it is at most 2^32 (a unit component) after rounding.
    const wide::DivResult qr = wide::Default::div(wide::U128{m[i] >> 32, m[i] << 32}, length);
    const bool over_half = (qr.remainder >> 63) != 0 || (qr.remainder << 1) > length;
    const bool tie = (qr.remainder >> 63) == 0 && (qr.remainder << 1) == length;
    const std::uint64_t q =
        qr.quotient + ((over_half || (tie && (qr.quotient & 1U) != 0)) ? 1U : 0U);
    c[i] = signed_saturate(c[i] < 0, q);
  }
  return true;
}

}  // namespace detsim::detail

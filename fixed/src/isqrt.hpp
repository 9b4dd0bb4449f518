// Correctly rounded integer square roots: the one mechanism behind hypot (roots.cpp), the lengths
// of vectors (vector.cpp) and normalisation (normalize.hpp). Internal to the fixed module; not
// installed.
#pragma once

#include <cstdint>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/wide.hpp>

namespace detsim::detail {

/// round(sqrt(n)) for any unsigned 128-bit n, correctly rounded (the square root of an integer is
/// never exactly halfway between two integers, so there are no ties). The result is at most
/// 2^64 - 1: for n > 2^128 - 2^64, where it would round to 2^64, it saturates to 2^64 - 1.
/// Integer arithmetic only, no division; defined in roots.cpp.
[[nodiscard]] std::uint64_t isqrt_round(wide::U128 n) noexcept;

/// An estimate of 1/sqrt(n) for n in [2^124, 2^128) (the sums of squares of normalize.hpp):
/// reciprocal 2^(shift - 125) = (1 + b) / sqrt(n) with |b| < 2^-41.49 (a proven bound; see
/// roots.cpp), where shift is 1 for n < 2^126, else 0 (n 4^shift is in [2^126, 2^128)), and
/// reciprocal < 2^62 + 4.
struct ReciprocalRoot {
  std::uint64_t reciprocal;
  unsigned shift;
};

/// The estimate above, from the first steps of isqrt_round (no rounding, no division); defined in
/// roots.cpp.
[[nodiscard]] ReciprocalRoot reciprocal_root(wide::U128 n) noexcept;

/// x^2 + y^2 of two raw values, exact: each square is at most 2^126, so the sum fits.
[[nodiscard]] constexpr wide::U128 sum_of_squares(std::int64_t x, std::int64_t y) noexcept {
  const std::uint64_t ax = magnitude(x);
  const std::uint64_t ay = magnitude(y);
  return wide::add(wide::Default::mul(ax, ax), wide::Default::mul(ay, ay));
}

/// x^2 + y^2 + z^2 of three raw values, exact: the sum is at most 3 * 2^126 < 2^128.
[[nodiscard]] constexpr wide::U128 sum_of_squares(std::int64_t x, std::int64_t y,
                                                  std::int64_t z) noexcept {
  const std::uint64_t az = magnitude(z);
  return wide::add(sum_of_squares(x, y), wide::Default::mul(az, az));
}

/// Raw bits of sqrt(x^2 + y^2) for raw Q32.32 values x and y: correctly rounded, saturated to
/// INT64_MAX. Squaring raw values keeps the Q32.32 scale: sqrt(X^2 + Y^2) for X = x * 2^32 is
/// 2^32 * sqrt(x^2 + y^2). Any sign, including INT64_MIN.
[[nodiscard]] inline std::int64_t hypot_raw(std::int64_t x, std::int64_t y) noexcept {
  const std::uint64_t root = isqrt_round(sum_of_squares(x, y));  // <= 2^63.5
  return root > static_cast<std::uint64_t>(raw_max) ? raw_max : static_cast<std::int64_t>(root);
}

/// Raw bits of sqrt(x^2 + y^2 + z^2) (a 3-vector's length) for raw Q32.32 components: correctly
/// rounded, saturated to INT64_MAX. No intermediate overflow for any components.
[[nodiscard]] inline std::int64_t hypot_raw(std::int64_t x, std::int64_t y,
                                            std::int64_t z) noexcept {
  const std::uint64_t root = isqrt_round(sum_of_squares(x, y, z));  // <= sqrt(3) 2^63 < 2^64
  return root > static_cast<std::uint64_t>(raw_max) ? raw_max : static_cast<std::int64_t>(root);
}

}  // namespace detsim::detail

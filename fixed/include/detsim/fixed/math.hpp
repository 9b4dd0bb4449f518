// Functions of Fixed, in integer arithmetic only.
//
// Accuracy (measured against MPFR by tests/fixed_accuracy_test.cpp, table in docs/ACCURACY.md):
// - sqrt, rsqrt and hypot are correctly rounded (error <= 0.5 ulp, ulp = 2^-32).
// - Every other function is faithfully rounded: error < 1 ulp where |result| < 2^16, relative error
//   < 2^-46 where the result is larger (exp, exp2, pow, tan near its poles).
// - Results that do not fit saturate to Fixed::max() / Fixed::min().
// Domain errors never trap; each function below documents the value it returns.
#pragma once

#include <detsim/fixed/fixed.hpp>

namespace detsim {

// ---- Rounding and selection (exact) ------------------------------------------------------------

/// |x|; abs(Fixed::min()) saturates to Fixed::max().
[[nodiscard]] constexpr Fixed abs(Fixed x) noexcept {
  return x.raw() < 0 ? -x : x;
}

/// Largest integer <= x. Exact; never saturates.
[[nodiscard]] constexpr Fixed floor(Fixed x) noexcept {
  return Fixed::from_raw(
      static_cast<std::int64_t>(static_cast<std::uint64_t>(x.raw()) & ~std::uint64_t{0xFFFFFFFFU}));
}

/// Smallest integer >= x; values above 2^31 - 1 saturate to Fixed::max().
[[nodiscard]] constexpr Fixed ceil(Fixed x) noexcept {
  const Fixed f = floor(x);
  return f == x ? x : f + Fixed::one();
}

/// Integer part, rounding toward zero. Exact; never saturates.
[[nodiscard]] constexpr Fixed trunc(Fixed x) noexcept {
  return x.raw() < 0 ? ceil(x) : floor(x);
}

/// Nearest integer, ties to even (the library's one rounding rule: round(2.5) == 2,
/// round(-0.5) == 0). Values of 2^31 - 0.5 and above saturate to Fixed::max().
[[nodiscard]] constexpr Fixed round(Fixed x) noexcept {
  return x >> 32 << 32;
}

/// x - floor(x), in [0, 1). Exact.
[[nodiscard]] constexpr Fixed frac(Fixed x) noexcept {
  return Fixed::from_raw(
      static_cast<std::int64_t>(static_cast<std::uint64_t>(x.raw()) & 0xFFFFFFFFU));
}

[[nodiscard]] constexpr Fixed min(Fixed a, Fixed b) noexcept {
  return b < a ? b : a;
}
[[nodiscard]] constexpr Fixed max(Fixed a, Fixed b) noexcept {
  return a < b ? b : a;
}

/// x limited to [lo, hi]. If lo > hi the result is lo (defined, unlike std::clamp).
[[nodiscard]] constexpr Fixed clamp(Fixed x, Fixed lo, Fixed hi) noexcept {
  return max(lo, min(x, hi));
}

/// a + (b - a) * t, computed exactly (b - a is not rounded or saturated) and then rounded to
/// nearest, ties to even, and saturated. lerp(a, b, 0) == a and lerp(a, b, 1) == b for all a, b.
[[nodiscard]] constexpr Fixed lerp(Fixed a, Fixed b, Fixed t) noexcept;

// ---- Roots ------------------------------------------------------------------------------------

/// Square root, correctly rounded. sqrt(x) for x < 0 returns 0.
[[nodiscard]] Fixed sqrt(Fixed x) noexcept;

/// 1 / sqrt(x), correctly rounded (results up to 2^16, at x = 2^-32). rsqrt(x) for x <= 0 returns
/// Fixed::max().
[[nodiscard]] Fixed rsqrt(Fixed x) noexcept;

/// sqrt(x^2 + y^2), correctly rounded, with no intermediate overflow; saturates to Fixed::max().
[[nodiscard]] Fixed hypot(Fixed x, Fixed y) noexcept;
/// hypot(x, y) > limit, decided exactly from x^2 + y^2 without taking the root: the same answer as
/// the comparison of hypot's rounded, saturated result for every input, at the cost of two
/// multiplies (the friction clamp of the contact solver asks this in every iteration).
[[nodiscard]] constexpr bool hypot_exceeds(Fixed x, Fixed y, Fixed limit) noexcept;

// ---- Trigonometry (radians) -------------------------------------------------------------------

// sin and cos do better than faithful: error < 0.5 + 2^-26 ulp, so each result is the correctly
// rounded one unless the exact value lies within 2^-26 ulp of a tie. Range reduction is exact
// over the whole Fixed range (every |x| < 2^31).

/// Sine. sin(-x) == -sin(x) bit for bit (x != Fixed::min()); nondecreasing on [-pi/2, pi/2];
/// sin(0) == 0.
[[nodiscard]] Fixed sin(Fixed x) noexcept;
/// Cosine. cos(-x) == cos(x) bit for bit; nonincreasing on [0, pi]; cos(0) == 1.
[[nodiscard]] Fixed cos(Fixed x) noexcept;

struct SinCos {
  Fixed sin;
  Fixed cos;
};
/// Sine and cosine together (one range reduction). Each is faithfully rounded and the pair always
/// satisfies sin^2 + cos^2 <= 1 in exact arithmetic. Where (sin(x), cos(x)) would break that
/// (about half of all arguments: rounding both to nearest leaves the circle as often as not),
/// components rounded away from zero are taken one ulp toward zero, which keeps them faithful:
/// the one rounded up by more if that suffices, else the other one, else both (the faithful pair
/// inside the circle nearest to the exact point). So each component is sin(x) or cos(x), or one
/// ulp nearer to zero, and sincos(-x) mirrors sincos(x) bit for bit.
[[nodiscard]] SinCos sincos(Fixed x) noexcept;

/// Tangent. Faithful where |tan| < 2^16, relative error < 2^-46 above. Beyond the range, at the
/// raw neighbours of the poles, it saturates to Fixed::max() / Fixed::min() with the sign of the
/// exact value. tan(-x) == -tan(x) except where the result saturates.
[[nodiscard]] Fixed tan(Fixed x) noexcept;

// asin, acos, atan and atan2 do better than faithful: error < 0.5 + 2^-16 ulp, so each result is
// the correctly rounded one unless the exact value lies within 2^-16 ulp of a tie. atan and asin
// are exactly odd and atan2 is exactly antisymmetric in y (y != Fixed::min()).

/// Arcsine in [-pi/2, pi/2]. Inputs outside [-1, 1] are clamped to it (asin(2) == pi/2).
[[nodiscard]] Fixed asin(Fixed x) noexcept;
/// Arccosine in [0, pi]. Inputs outside [-1, 1] are clamped to it (acos(-2) == pi).
[[nodiscard]] Fixed acos(Fixed x) noexcept;
/// Arctangent in (-pi/2, pi/2).
[[nodiscard]] Fixed atan(Fixed x) noexcept;
/// Angle of the point (x, y) in [-pi, pi]; atan2(0, 0) == 0, atan2(0, x < 0) == pi and
/// atan2(y, 0) == +-pi/2 for y != 0.
[[nodiscard]] Fixed atan2(Fixed y, Fixed x) noexcept;

// ---- Exponentials and logarithms --------------------------------------------------------------

/// e^x. Saturates to Fixed::max() above ln(2^31); results below 2^-33 round to 0. exp(0) == 1.
[[nodiscard]] Fixed exp(Fixed x) noexcept;
/// 2^x. Saturates to Fixed::max() for x >= 31; results below 2^-33 round to 0 (2^-33 itself is a
/// tie and rounds to even: 0). Exact for integer x: exp2(k) == 2^k.
[[nodiscard]] Fixed exp2(Fixed x) noexcept;
/// Natural logarithm. log(x) for x <= 0 returns Fixed::min() (the saturated -infinity).
[[nodiscard]] Fixed log(Fixed x) noexcept;
/// Base-2 logarithm, exact for powers of two. log2(x) for x <= 0 returns Fixed::min().
[[nodiscard]] Fixed log2(Fixed x) noexcept;
/// x^y. For x > 0: e^(y ln x). pow(0, y) is 0 for y > 0, 1 for y == 0 and Fixed::max() for y < 0.
/// For x < 0 and integer y the sign follows y's parity; x < 0 with a non-integer y returns 0.
/// pow(x, 0) == 1 and pow(x, 1) == x for every x; for an integer y from 2 to 63 a representable
/// exact result is returned exactly (pow(3, 19) == 1162261467), as repeated multiplication gives.
[[nodiscard]] Fixed pow(Fixed x, Fixed y) noexcept;

// ---- Inline definitions -----------------------------------------------------------------------
constexpr bool hypot_exceeds(Fixed x, Fixed y, Fixed limit) noexcept {
  // hypot's raw is the rounded root of n = X^2 + Y^2 (exact: < 2^127), saturated.
  const std::uint64_t ax = detail::magnitude(x.raw());
  const std::uint64_t ay = detail::magnitude(y.raw());
  return detail::root_exceeds(wide::add(wide::Default::mul(ax, ax), wide::Default::mul(ay, ay)),
                              limit.raw());
}

constexpr Fixed lerp(Fixed a, Fixed b, Fixed t) noexcept {
  // (b - a) needs 65 bits: carry it as sign + 64-bit magnitude.
  const bool diff_negative = b < a;
  const std::uint64_t diff =
      diff_negative ? static_cast<std::uint64_t>(a.raw()) - static_cast<std::uint64_t>(b.raw())
                    : static_cast<std::uint64_t>(b.raw()) - static_cast<std::uint64_t>(a.raw());
  const bool negative = diff_negative != (t.raw() < 0);
  const wide::U128 product = wide::Default::mul(diff, detail::magnitude(t.raw()));
  // |product| >= 2^126 means |(b - a) t| >= 2^94, far beyond any a: the result saturates. Checking
  // it here also keeps the 128-bit sum below from overflowing.
  if ((product.hi >> 62) != 0) return negative ? Fixed::min() : Fixed::max();
  // a + product / 2^32, rounded: round the whole sum at once so the tie rule sees the exact value.
  // Work with 2^32 * a as a signed 128-bit value and add or subtract the product.
  const std::int64_t ar = a.raw();
  const wide::U128 a_scaled =
      wide::shl(wide::U128{ar < 0 ? ~std::uint64_t{0} : 0, static_cast<std::uint64_t>(ar)},
                Fixed::fraction_bits);
  const wide::U128 sum = negative ? wide::sub(a_scaled, product) : wide::add(a_scaled, product);
  // The exact sum lies between a*2^32 and b*2^32 (|t| <= 1) or beyond (|t| > 1); its magnitude is
  // below 2^127 because |diff * t| < 2^126 and |a * 2^32| <= 2^95.
  const bool sum_negative = (sum.hi >> 63) != 0;
  const wide::U128 mag = sum_negative ? wide::negate(sum) : sum;
  return Fixed::from_raw(
      detail::signed_saturate(sum_negative, detail::round_shift_right(mag, Fixed::fraction_bits)));
}

}  // namespace detsim

// Fixed's operators: rounding (ties to even), saturation, division by zero, shifts, conversions and
// the exact helpers of math.hpp. Expected values come from hand derivation or from an exact check
// of the rounding inequality, never from the implementation under test.
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/math.hpp>

#include "support/print.hpp"

namespace detsim {
namespace {

constexpr std::int64_t kOne = Fixed::one_raw;
constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMin = std::numeric_limits<std::int64_t>::min();

Fixed raw(std::int64_t r) {
  return Fixed::from_raw(r);
}

// Operands that exercise every boundary: zero, ulps, integers, halves, extremes.
std::vector<std::int64_t> edge_raws() {
  std::vector<std::int64_t> v = {0,         1,        -1,         2,          -2,
                                 kOne,      -kOne,    kOne + 1,   kOne - 1,   kOne / 2,
                                 -kOne / 2, kMax,     kMax - 1,   kMin,       kMin + 1,
                                 kMax / 2,  kMin / 2, 0x7FFFFFFF, 0x80000000, -0x80000000LL,
                                 3,         5};
  for (int s = 0; s < 63; s += 7) {
    v.push_back(std::int64_t{1} << s);
    v.push_back(-(std::int64_t{1} << s));
    v.push_back((std::int64_t{1} << s) + 1);
  }
  return v;
}

std::vector<std::int64_t> random_raws(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::int64_t> v;
  v.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    // Half uniform over all bits, half with a random magnitude so small values are common too.
    const std::uint64_t bits = rng();
    const unsigned width = static_cast<unsigned>(rng() % 64);
    const std::uint64_t mag = i % 2 == 0 ? bits : (width == 0 ? 0 : bits >> (64 - width));
    v.push_back(static_cast<std::int64_t>(mag));
  }
  return v;
}

// Exact signed 128-bit value as sign + magnitude, for the verification inequalities below.
struct Signed128 {
  bool negative;
  wide::U128 mag;
};

Signed128 product(std::int64_t a, std::int64_t b) {
  const auto ma = a < 0 ? 0U - static_cast<std::uint64_t>(a) : static_cast<std::uint64_t>(a);
  const auto mb = b < 0 ? 0U - static_cast<std::uint64_t>(b) : static_cast<std::uint64_t>(b);
  return {(a < 0) != (b < 0), wide::Portable::mul(ma, mb)};
}

// |x - y| for signed 128-bit values given as sign + magnitude (magnitudes < 2^127).
wide::U128 distance(Signed128 x, Signed128 y) {
  if (x.negative == y.negative)
    return wide::less(x.mag, y.mag) ? wide::sub(y.mag, x.mag) : wide::sub(x.mag, y.mag);
  return wide::add(x.mag, y.mag);
}

Signed128 scaled(std::int64_t q, unsigned shift) {  // q * 2^shift
  const auto mq = q < 0 ? 0U - static_cast<std::uint64_t>(q) : static_cast<std::uint64_t>(q);
  return {q < 0, wide::shl(wide::U128{0, mq}, shift)};
}

// True iff |exact| / 2^32 is beyond the largest magnitude of its sign by half an ulp or more, so
// that rounding it would leave the range and the saturated extreme is the right answer.
bool beyond_range(Signed128 exact) {
  const std::uint64_t limit =
      exact.negative ? std::uint64_t{1} << 63 : static_cast<std::uint64_t>(kMax);
  // 2 |exact| >= (2 limit + 1) 2^32
  const wide::U128 bound =
      wide::shl(wide::add(wide::shl(wide::U128{0, limit}, 1), wide::U128{0, 1}), 32);
  return !wide::less(wide::shl(exact.mag, 1), bound);
}

::testing::AssertionResult mul_is_correct(std::int64_t a, std::int64_t b, std::int64_t q) {
  const Signed128 exact = product(a, b);
  const wide::U128 half{0, std::uint64_t{1} << 31};
  const wide::U128 d = distance(exact, scaled(q, 32));
  if (wide::less(d, half)) return ::testing::AssertionSuccess();
  if (d == half && (q & 1) == 0) return ::testing::AssertionSuccess();
  if (q == (exact.negative ? kMin : kMax) && beyond_range(exact))
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "a=" << a << " b=" << b << " got raw " << q;
}

TEST(FixedConstruction, FromIntAndRawAreExact) {
  EXPECT_EQ(Fixed::from_int(0).raw(), 0);
  EXPECT_EQ(Fixed::from_int(1).raw(), kOne);
  EXPECT_EQ(Fixed::from_int(-1).raw(), -kOne);
  EXPECT_EQ(Fixed::from_int(std::numeric_limits<std::int32_t>::min()).raw(), kMin);
  EXPECT_EQ(Fixed::from_int(std::numeric_limits<std::int32_t>::max()).raw(),
            std::int64_t{0x7FFFFFFF} * kOne);
  EXPECT_EQ(Fixed::from_raw(12345).raw(), 12345);
  EXPECT_EQ(Fixed{}.raw(), 0);
  static_assert(Fixed::from_int(3) * Fixed::from_int(4) == Fixed::from_int(12));
  static_assert(Fixed::one() / Fixed::from_int(4) == Fixed::from_raw(kOne / 4));
}

TEST(FixedConversion, ToIntRoundsHalfToEven) {
  EXPECT_EQ(raw(kOne / 2).to_int(), 0);             // 0.5 -> 0
  EXPECT_EQ(raw(kOne + kOne / 2).to_int(), 2);      // 1.5 -> 2
  EXPECT_EQ(raw(2 * kOne + kOne / 2).to_int(), 2);  // 2.5 -> 2
  EXPECT_EQ(raw(-kOne / 2).to_int(), 0);            // -0.5 -> 0
  EXPECT_EQ(raw(-kOne - kOne / 2).to_int(), -2);    // -1.5 -> -2
  EXPECT_EQ(raw(kOne / 2 + 1).to_int(), 1);
  EXPECT_EQ(raw(-kOne / 2 - 1).to_int(), -1);
  EXPECT_EQ(Fixed::max().to_int(), std::numeric_limits<std::int32_t>::max());  // saturates
  EXPECT_EQ(Fixed::min().to_int(), std::numeric_limits<std::int32_t>::min());
  EXPECT_EQ(raw(1).to_double(), 1.0 / 4294967296.0);
}

TEST(FixedAddSub, SaturatesAtTheExtremes) {
  EXPECT_EQ(Fixed::max() + Fixed::epsilon(), Fixed::max());
  EXPECT_EQ(Fixed::min() - Fixed::epsilon(), Fixed::min());
  EXPECT_EQ(Fixed::max() + Fixed::max(), Fixed::max());
  EXPECT_EQ(Fixed::min() + Fixed::min(), Fixed::min());
  EXPECT_EQ(Fixed::max() - Fixed::min(), Fixed::max());
  EXPECT_EQ(Fixed::min() - Fixed::max(), Fixed::min());
  EXPECT_EQ(Fixed::max() + Fixed::min(), raw(-1));
  EXPECT_EQ(Fixed{} - Fixed::min(), Fixed::max());
  EXPECT_EQ(-Fixed::min(), Fixed::max());
  EXPECT_EQ(-Fixed::max(), raw(kMin + 1));
}

TEST(FixedAddSub, MatchesExactSumOrSaturation) {
  const auto values = random_raws(200000, 1);
  for (std::size_t i = 0; i + 1 < values.size(); i += 2) {
    const std::int64_t a = values[i];
    const std::int64_t b = values[i + 1];
    // Exact sums in 128 bits via sign-magnitude, then clamp: an independent formulation.
    const Signed128 sa = scaled(a, 0);
    const Signed128 sb = scaled(b, 0);
    const std::int64_t want_sum = [&] {
      if (a >= 0 && b >= 0)
        return wide::less(wide::U128{0, static_cast<std::uint64_t>(kMax)},
                          wide::add(sa.mag, sb.mag))
                   ? kMax
                   : a + b;
      if (a < 0 && b < 0)
        return wide::less(wide::U128{0, std::uint64_t{1} << 63}, wide::add(sa.mag, sb.mag))
                   ? kMin
                   : static_cast<std::int64_t>(0U - (sa.mag.lo + sb.mag.lo));
      return static_cast<std::int64_t>(static_cast<std::uint64_t>(a) +
                                       static_cast<std::uint64_t>(b));
    }();
    ASSERT_EQ((raw(a) + raw(b)).raw(), want_sum) << a << " + " << b;
    // a - b == a + (-b) except where -b saturates (b == min).
    if (b != kMin) {
      ASSERT_EQ(raw(a) - raw(b), raw(a) + (-raw(b))) << a << " - " << b;
    }
  }
}

TEST(FixedMul, HandDerivedValues) {
  EXPECT_EQ(Fixed::from_int(3) * Fixed::from_int(-7), Fixed::from_int(-21));
  EXPECT_EQ(raw(kOne / 2) * raw(kOne / 2), raw(kOne / 4));
  // 2^-32 * 0.5 = 2^-33: a tie between 0 and 2^-32, rounds to even (0).
  EXPECT_EQ(raw(1) * raw(kOne / 2), raw(0));
  // 3 ulp * 0.5 = 1.5 ulp: tie between 1 and 2, rounds to even (2).
  EXPECT_EQ(raw(3) * raw(kOne / 2), raw(2));
  EXPECT_EQ(raw(-3) * raw(kOne / 2), raw(-2));
  // 5 ulp * 0.5 = 2.5 ulp -> 2; 0.75 ulp rounds to 1.
  EXPECT_EQ(raw(5) * raw(kOne / 2), raw(2));
  EXPECT_EQ(raw(3) * raw(kOne / 4), raw(1));
  EXPECT_EQ(raw(1) * raw(kOne / 4), raw(0));
  EXPECT_EQ(Fixed::max() * Fixed::max(), Fixed::max());
  EXPECT_EQ(Fixed::min() * Fixed::min(), Fixed::max());
  EXPECT_EQ(Fixed::min() * Fixed::max(), Fixed::min());
  EXPECT_EQ(Fixed::min() * Fixed::one(), Fixed::min());
  EXPECT_EQ(Fixed::min() * -Fixed::one(), Fixed::max());
  EXPECT_EQ(Fixed::from_int(65536) * Fixed::from_int(32768), Fixed::max());   // 2^31 saturates
  EXPECT_EQ(Fixed::from_int(65536) * Fixed::from_int(-32768), Fixed::min());  // -2^31 fits
  EXPECT_EQ(Fixed::from_int(3) * 4, Fixed::from_int(12));
  EXPECT_EQ(-2 * Fixed::from_int(3), Fixed::from_int(-6));
}

TEST(FixedMul, CorrectlyRoundedOnRandomAndEdgeOperands) {
  std::vector<std::int64_t> values = edge_raws();
  const auto randoms = random_raws(400000, 2);
  values.insert(values.end(), randoms.begin(), randoms.end());
  const auto edges = edge_raws();
  for (const std::int64_t a : edges) {
    for (const std::int64_t b : values) {
      ASSERT_TRUE(mul_is_correct(a, b, (raw(a) * raw(b)).raw()));
    }
  }
  for (std::size_t i = 0; i + 1 < randoms.size(); ++i) {
    ASSERT_TRUE(
        mul_is_correct(randoms[i], randoms[i + 1], (raw(randoms[i]) * raw(randoms[i + 1])).raw()));
    ASSERT_EQ(raw(randoms[i]) * raw(randoms[i + 1]), raw(randoms[i + 1]) * raw(randoms[i]));
  }
}

::testing::AssertionResult div_is_correct(std::int64_t a, std::int64_t b, std::int64_t q) {
  // q is correct iff |a * 2^32 - q * b| <= |b| / 2, with equality only for even q; or q is the
  // saturated extreme of the right sign and the exact quotient is beyond it.
  const Signed128 exact = scaled(a, 32);
  const Signed128 qb = product(q, b);
  const wide::U128 d = distance(exact, qb);
  const wide::U128 twice_d = wide::shl(d, 1);
  const auto mb = b < 0 ? 0U - static_cast<std::uint64_t>(b) : static_cast<std::uint64_t>(b);
  const wide::U128 divisor{0, mb};
  if (wide::less(twice_d, divisor)) return ::testing::AssertionSuccess();
  if (twice_d == divisor && (q & 1) == 0) return ::testing::AssertionSuccess();
  // Saturated: the exact quotient a 2^32 / b is at least half an ulp beyond the extreme, i.e.
  // 2 |a| 2^32 >= (2 limit + 1) |b|.
  const bool quotient_negative = (a < 0) != (b < 0);
  if (q == (quotient_negative ? kMin : kMax)) {
    const std::uint64_t limit =
        quotient_negative ? std::uint64_t{1} << 63 : static_cast<std::uint64_t>(kMax);
    const wide::U128 bound = wide::add(wide::shl(wide::Portable::mul(limit, mb), 1), divisor);
    if (!wide::less(wide::shl(exact.mag, 1), bound)) return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << a << " / " << b << " gave raw " << q;
}

TEST(FixedDiv, HandDerivedValues) {
  EXPECT_EQ(Fixed::from_int(1) / Fixed::from_int(4), raw(kOne / 4));
  EXPECT_EQ(Fixed::from_int(-21) / Fixed::from_int(7), Fixed::from_int(-3));
  // 1 ulp / 2 = 0.5 ulp: tie -> 0. 3 ulp / 2 -> 2 (tie to even). 1 ulp / 3 -> 0.
  EXPECT_EQ(raw(1) / Fixed::from_int(2), raw(0));
  EXPECT_EQ(raw(3) / Fixed::from_int(2), raw(2));
  EXPECT_EQ(raw(-3) / Fixed::from_int(2), raw(-2));
  EXPECT_EQ(raw(2) / Fixed::from_int(3), raw(1));
  // 1/3 = 0x55555555.555... ulp -> 0x55555555; 2/3 = 0xAAAAAAAA.AAA... -> 0xAAAAAAAB.
  EXPECT_EQ(Fixed::one() / Fixed::from_int(3), raw(0x55555555));
  EXPECT_EQ(Fixed::from_int(2) / Fixed::from_int(3), raw(0xAAAAAAAB));
  // Division by zero: saturate with the dividend's sign; 0/0 = 0. Never traps.
  EXPECT_EQ(Fixed::one() / Fixed{}, Fixed::max());
  EXPECT_EQ(-Fixed::one() / Fixed{}, Fixed::min());
  EXPECT_EQ(Fixed{} / Fixed{}, Fixed{});
  EXPECT_EQ(Fixed::min() / Fixed{}, Fixed::min());
  // min / -1 = 2^31 does not fit: saturates to max.
  EXPECT_EQ(Fixed::min() / -Fixed::one(), Fixed::max());
  EXPECT_EQ(Fixed::min() / Fixed::one(), Fixed::min());
  EXPECT_EQ(Fixed::max() / raw(1), Fixed::max());
  EXPECT_EQ(Fixed::max() / raw(-1), Fixed::min());
  EXPECT_EQ(Fixed::min() / Fixed::min(), Fixed::one());
  EXPECT_EQ(raw(1) / Fixed::max(), raw(0));
}

TEST(FixedDiv, CorrectlyRoundedOnRandomAndEdgeOperands) {
  const auto edges = edge_raws();
  const auto randoms = random_raws(400000, 3);
  for (const std::int64_t a : edges) {
    for (const std::int64_t b : edges) {
      if (b == 0) continue;
      ASSERT_TRUE(div_is_correct(a, b, (raw(a) / raw(b)).raw()));
    }
    for (const std::int64_t b : randoms) {
      if (b == 0) continue;
      ASSERT_TRUE(div_is_correct(a, b, (raw(a) / raw(b)).raw()));
      ASSERT_TRUE(div_is_correct(b, a == 0 ? 1 : a, (raw(b) / raw(a == 0 ? 1 : a)).raw()));
    }
  }
  for (std::size_t i = 0; i + 1 < randoms.size(); ++i) {
    if (randoms[i + 1] == 0) continue;
    ASSERT_TRUE(
        div_is_correct(randoms[i], randoms[i + 1], (raw(randoms[i]) / raw(randoms[i + 1])).raw()));
  }
}

TEST(FixedShift, LeftSaturatesRightRoundsHalfToEven) {
  EXPECT_EQ(Fixed::one() << 3, Fixed::from_int(8));
  EXPECT_EQ(Fixed::from_int(-3) << 2, Fixed::from_int(-12));
  EXPECT_EQ(Fixed::one() << 31, Fixed::max());
  EXPECT_EQ(-Fixed::one() << 31, Fixed::min());  // -2^31 fits exactly
  EXPECT_EQ(-Fixed::one() << 32, Fixed::min());
  EXPECT_EQ(raw(1) << 62, raw(std::int64_t{1} << 62));
  EXPECT_EQ(raw(1) << 63, Fixed::max());
  EXPECT_EQ(raw(1) << 1000, Fixed::max());
  EXPECT_EQ(raw(-1) << 63, Fixed::min());
  EXPECT_EQ(Fixed{} << 100, Fixed{});
  EXPECT_EQ(raw(3) >> 1, raw(2));  // 1.5 -> 2
  EXPECT_EQ(raw(5) >> 1, raw(2));  // 2.5 -> 2
  EXPECT_EQ(raw(-3) >> 1, raw(-2));
  EXPECT_EQ(raw(-5) >> 1, raw(-2));
  EXPECT_EQ(raw(7) >> 2, raw(2));  // 1.75 -> 2
  EXPECT_EQ(raw(kMax) >> 63, raw(1));
  EXPECT_EQ(raw(kMin) >> 63, raw(-1));
  EXPECT_EQ(raw(kMin) >> 64, raw(0));  // -0.5 -> 0
  EXPECT_EQ(raw(kMax) >> 64, raw(0));
  EXPECT_EQ(raw(kMax) >> 1000, raw(0));
  EXPECT_EQ(Fixed::one() >> -2, Fixed::from_int(4));
  EXPECT_EQ(Fixed::from_int(4) << -2, Fixed::one());
  EXPECT_EQ(Fixed::one() << std::numeric_limits<int>::min(), Fixed{});
  EXPECT_EQ(Fixed::one() >> std::numeric_limits<int>::min(), Fixed::max());
  // x >> n equals x / 2^n (both correctly rounded) wherever 2^n is representable.
  for (const std::int64_t a : random_raws(20000, 4)) {
    for (int n = 0; n <= 30; n += 3) {
      ASSERT_EQ(raw(a) >> n, raw(a) / Fixed::from_int(1 << n)) << a << " >> " << n;
      ASSERT_EQ(raw(a) << n, raw(a) * Fixed::from_int(1 << n)) << a << " << " << n;
    }
  }
}

TEST(FixedCompare, OrdersByValue) {
  EXPECT_LT(Fixed::min(), Fixed{});
  EXPECT_LT(raw(-1), raw(0));
  EXPECT_GT(Fixed::max(), Fixed::one());
  EXPECT_EQ(Fixed::from_int(2), raw(2 * kOne));
  EXPECT_NE(Fixed::from_int(2), raw(2 * kOne + 1));
  Fixed x = Fixed::one();
  x += Fixed::one();
  x *= Fixed::from_int(3);
  x -= Fixed::one();
  x /= Fixed::from_int(5);
  x <<= 2;
  x >>= 1;
  EXPECT_EQ(x, Fixed::from_int(2));
}

TEST(FixedExactHelpers, FloorCeilRoundTruncFrac) {
  const Fixed two_and_half = raw(2 * kOne + kOne / 2);
  EXPECT_EQ(floor(two_and_half), Fixed::from_int(2));
  EXPECT_EQ(ceil(two_and_half), Fixed::from_int(3));
  EXPECT_EQ(round(two_and_half), Fixed::from_int(2));
  EXPECT_EQ(round(raw(3 * kOne + kOne / 2)), Fixed::from_int(4));
  EXPECT_EQ(round(-two_and_half), Fixed::from_int(-2));
  EXPECT_EQ(trunc(-two_and_half), Fixed::from_int(-2));
  EXPECT_EQ(floor(-two_and_half), Fixed::from_int(-3));
  EXPECT_EQ(ceil(-two_and_half), Fixed::from_int(-2));
  EXPECT_EQ(frac(-two_and_half), raw(kOne / 2));
  EXPECT_EQ(floor(Fixed::min()), Fixed::min());
  EXPECT_EQ(trunc(Fixed::min()), Fixed::min());
  EXPECT_EQ(ceil(Fixed::max()), Fixed::max());  // 2^31 saturates
  EXPECT_EQ(round(Fixed::max()), Fixed::max());
  EXPECT_EQ(abs(Fixed::min()), Fixed::max());
  EXPECT_EQ(abs(-two_and_half), two_and_half);
  for (const std::int64_t a : random_raws(100000, 5)) {
    const Fixed x = raw(a);
    const Fixed f = floor(x);
    ASSERT_EQ(f.raw() % kOne, 0);
    ASSERT_LE(f, x);
    ASSERT_EQ(f + frac(x), x);
    ASSERT_GE(frac(x), Fixed{});
    ASSERT_LT(frac(x), Fixed::one());
    if (x < Fixed::from_int(0x7FFFFFFF)) {
      ASSERT_GE(ceil(x), x);
      ASSERT_LT(ceil(x) - x, Fixed::one());
    }
    ASSERT_LE(abs(trunc(x)), abs(x));
  }
}

TEST(FixedExactHelpers, MinMaxClamp) {
  const Fixed a = Fixed::from_int(-2);
  const Fixed b = Fixed::from_int(5);
  EXPECT_EQ(min(a, b), a);
  EXPECT_EQ(max(a, b), b);
  EXPECT_EQ(clamp(Fixed::from_int(9), a, b), b);
  EXPECT_EQ(clamp(Fixed::from_int(-9), a, b), a);
  EXPECT_EQ(clamp(Fixed::one(), a, b), Fixed::one());
  EXPECT_EQ(clamp(Fixed::one(), b, a), b);  // lo > hi: documented to give lo
}

TEST(FixedExactHelpers, LerpIsExactThenRoundedOnce) {
  EXPECT_EQ(lerp(Fixed::from_int(2), Fixed::from_int(6), Fixed::half()), Fixed::from_int(4));
  EXPECT_EQ(lerp(Fixed::min(), Fixed::max(), Fixed{}), Fixed::min());
  EXPECT_EQ(lerp(Fixed::min(), Fixed::max(), Fixed::one()), Fixed::max());
  // b - a overflows Fixed here, but lerp's difference is exact: midpoint of [min, max] is -0.5 ulp,
  // a tie between -1 ulp and 0 that rounds to the even 0.
  EXPECT_EQ(lerp(Fixed::min(), Fixed::max(), Fixed::half()), Fixed{});
  EXPECT_EQ(lerp(Fixed::max(), Fixed::min(), Fixed::half()), Fixed{});
  EXPECT_EQ(lerp(Fixed{}, Fixed::max(), Fixed::max()), Fixed::max());
  EXPECT_EQ(lerp(Fixed{}, Fixed::max(), Fixed::min()), Fixed::min());
  EXPECT_EQ(lerp(Fixed::min(), Fixed::max(), Fixed::min()), Fixed::min());
  EXPECT_EQ(lerp(Fixed::max(), Fixed::min(), Fixed::min()), Fixed::max());
  // Where b - a and the product are exact, lerp equals the plain expression.
  for (const std::int64_t s : random_raws(50000, 6)) {
    const Fixed a = raw(s >> 20);
    const Fixed b = raw(((s >> 4) * 7) >> 17);
    const Fixed t = raw(static_cast<std::int64_t>(static_cast<std::uint64_t>(s) % (2 * kOne)));
    ASSERT_EQ(lerp(a, b, t), a + (b - a) * t) << a.raw() << " " << b.raw() << " " << t.raw();
    ASSERT_EQ(lerp(a, b, Fixed{}), a);
    ASSERT_EQ(lerp(a, b, Fixed::one()), b);
  }
}

}  // namespace
}  // namespace detsim

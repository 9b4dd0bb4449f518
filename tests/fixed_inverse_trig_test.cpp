// atan, atan2, asin and acos: documented domain values, exact special angles, symmetries,
// consistency between the functions, and monotonicity.
//
// Expected values are derived here without the implementation: from the published hexadecimal
// expansion of pi, from Taylor series with bounded remainders, and from exact identities.
// The accuracy claim under test (math.hpp): error < 0.5 + 2^-16 ulp. So wherever the exact value is
// farther than 2^-16 ulp from a rounding tie, the result must be the correctly rounded value; where
// only two faithfully rounded results are compared, their difference is bounded by the sum of the
// errors.
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <detsim/fixed/math.hpp>

#include "support/print.hpp"

namespace detsim {
namespace {

__extension__ using u128 = unsigned __int128;

constexpr std::int64_t one_raw = std::int64_t{1} << 32;

Fixed raw(std::int64_t r) {
  return Fixed::from_raw(r);
}

// floor(pi * 2^124): the first 32 hexadecimal digits of pi, 3.243F6A8885A308D313198A2E0370734...
// (the same digits that seed Blowfish's P-array). Error < 2^-124.
constexpr u128 pi_q124 = (u128{0x3243F6A8885A308DU} << 64) | u128{0x313198A2E0370734U};

constexpr int dropped_bits = 124 - 32;  // from Q4.124 to Q32.32
constexpr u128 tie = u128{1} << (dropped_bits - 1);
// 2^-16 ulp, the slack of the accuracy claim, in units of 2^-124.
constexpr u128 claim_slack = u128{1} << (dropped_bits - 16);

// Whether a non-negative exact value v (units of 2^-124, known within `bound` units) is far enough
// from a rounding tie that the accuracy claim determines the result.
bool unambiguous(u128 v, u128 bound) {
  const u128 rest = v & ((u128{1} << dropped_bits) - 1);
  const u128 distance = rest > tie ? rest - tie : tie - rest;
  return distance > claim_slack + bound;
}

// v rounded to nearest, in raw Q32.32 units.
std::int64_t nearest_raw(u128 v) {
  return static_cast<std::int64_t>((v + tie) >> dropped_bits);
}

// Checks `got` (negated first when `negative`) against the exact value v >= 0: it must be the
// correctly rounded value, or either neighbour of v where v is too close to a tie to tell.
::testing::AssertionResult rounds(Fixed got, u128 v, u128 bound, bool negative = false) {
  const std::int64_t g = negative ? -got.raw() : got.raw();
  const auto floor_raw = static_cast<std::int64_t>(v >> dropped_bits);
  const bool ok =
      unambiguous(v, bound) ? g == nearest_raw(v) : (g == floor_raw || g == floor_raw + 1);
  if (ok) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << ::testing::PrintToString(got) << " is not the rounding of the exact value (nearest raw "
         << (negative ? -nearest_raw(v) : nearest_raw(v)) << ")";
}

// Correctly rounded multiples of pi: num * pi / den.
Fixed pi_times(unsigned num, unsigned den) {
  // num * pi_q124 < 2^128 for num <= 3; the truncation of pi and of the division add < 2 units.
  const u128 v = num * pi_q124 / den;
  EXPECT_TRUE(unambiguous(v, 2 * num)) << num << " pi / " << den << " is too close to a tie";
  return Fixed::from_raw(nearest_raw(v));
}

// ---- Documented domain values ----------------------------------------------------------------

TEST(InverseTrig, ConstantsMatchTheHexExpansionOfPi) {
  // Everything below compares with these, so check them first.
  EXPECT_EQ(Fixed::pi(), pi_times(1, 1));
  EXPECT_EQ(Fixed::half_pi(), pi_times(1, 2));
}

TEST(InverseTrig, Atan2OnTheAxes) {
  for (const std::int64_t r : {std::int64_t{1}, one_raw, 12345 * one_raw, INT64_MAX, INT64_MIN,
                               INT64_MIN + 1, std::int64_t{-1}, -one_raw}) {
    const Fixed v = raw(r);
    if (r > 0) {
      EXPECT_EQ(atan2(Fixed::zero(), v), Fixed::zero()) << "x = " << r;
      EXPECT_EQ(atan2(v, Fixed::zero()), Fixed::half_pi()) << "y = " << r;
    } else {
      EXPECT_EQ(atan2(Fixed::zero(), v), Fixed::pi()) << "x = " << r;  // documented: not -pi
      EXPECT_EQ(atan2(v, Fixed::zero()), -Fixed::half_pi()) << "y = " << r;
    }
  }
  EXPECT_EQ(atan2(Fixed::zero(), Fixed::zero()), Fixed::zero());
}

TEST(InverseTrig, AsinAcosClampOutsideTheDomain) {
  EXPECT_EQ(asin(Fixed::zero()), Fixed::zero());
  EXPECT_EQ(acos(Fixed::zero()), Fixed::half_pi());
  EXPECT_EQ(asin(Fixed::one()), Fixed::half_pi());
  EXPECT_EQ(asin(-Fixed::one()), -Fixed::half_pi());
  EXPECT_EQ(acos(Fixed::one()), Fixed::zero());
  EXPECT_EQ(acos(-Fixed::one()), Fixed::pi());
  for (const std::int64_t r : {one_raw + 1, 2 * one_raw, 1000 * one_raw, INT64_MAX}) {
    EXPECT_EQ(asin(raw(r)), Fixed::half_pi()) << r;
    EXPECT_EQ(acos(raw(r)), Fixed::zero()) << r;
  }
  for (const std::int64_t r : {-one_raw - 1, -2 * one_raw, INT64_MIN + 1, INT64_MIN}) {
    EXPECT_EQ(asin(raw(r)), -Fixed::half_pi()) << r;
    EXPECT_EQ(acos(raw(r)), Fixed::pi()) << r;
  }
}

// ---- Exactly known angles ----------------------------------------------------------------------

TEST(InverseTrig, DiagonalsAreMultiplesOfQuarterPi) {
  const Fixed quarter = pi_times(1, 4);
  const Fixed three_quarters = pi_times(3, 4);
  // pi/4 is also Fixed::pi() >> 2: pi() = pi 2^32 + d with |d| <= 1/2 and pi()'s raw value is 1
  // mod 4, so pi 2^30 = floor(pi() / 4) + 1/4 - d/4 lies in [1/8, 3/8] above an integer; both the
  // correctly rounded pi/4 and the shift (a tie-free rounding of +1/4) give that integer.
  ASSERT_EQ(Fixed::pi().raw() & 3, 1);
  EXPECT_EQ(quarter, Fixed::pi() >> 2);

  EXPECT_EQ(atan(Fixed::one()), quarter);
  EXPECT_EQ(atan(-Fixed::one()), -quarter);
  for (const std::int64_t r : {std::int64_t{1}, one_raw, 3 * one_raw / 7, 99 * one_raw, INT64_MAX,
                               std::int64_t{1} << 62}) {
    const Fixed v = raw(r);
    EXPECT_EQ(atan2(v, v), quarter) << r;
    EXPECT_EQ(atan2(v, -v), three_quarters) << r;
    EXPECT_EQ(atan2(-v, v), -quarter) << r;
    EXPECT_EQ(atan2(-v, -v), -three_quarters) << r;
  }
  EXPECT_EQ(atan2(Fixed::min(), Fixed::min()), -three_quarters);
}

TEST(InverseTrig, AsinAcosOfOneHalf) {
  // sin(pi/6) = 1/2 exactly, and 1/2 is representable.
  EXPECT_EQ(asin(Fixed::half()), pi_times(1, 6));
  EXPECT_EQ(asin(-Fixed::half()), -pi_times(1, 6));
  EXPECT_EQ(acos(Fixed::half()), pi_times(1, 3));
  EXPECT_EQ(acos(-Fixed::half()), pi_times(2, 3));
}

TEST(InverseTrig, AtanAndAsinOfSmallArgumentsAreTheArgument) {
  // |atan(x) - x| <= x^3 / 3 and |asin(x) - x| <= x^3 / 6 * 1.01 for x <= 2^-12: below 0.021 ulp,
  // so the correctly rounded value is x itself. Exhaustive over the 2^20 + 1 raw values.
  for (std::int64_t r = 0; r <= (std::int64_t{1} << 20); ++r) {
    const Fixed x = raw(r);
    ASSERT_EQ(atan(x), x);
    ASSERT_EQ(asin(x), x);
    ASSERT_EQ(atan(-x), -x);
    ASSERT_EQ(asin(-x), -x);
  }
}

TEST(InverseTrig, AtanOfLargeArguments) {
  // atan(x) = pi/2 - 1/x + r with 0 < r < 1/(3 x^3) <= 2^-73 (2^51 units of 2^-124) for x >= 2^24.
  for (const std::int64_t r :
       {std::int64_t{1} << 56, (std::int64_t{1} << 56) + 1, 123456789 * one_raw + 987654321,
        INT64_MAX / 3, INT64_MAX - 1, INT64_MAX}) {
    // 1/x in units of 2^-124 is 2^156 / r; (2^127 - 1) / r shifted left by 29 is within 2^29 + 1
    // units of it.
    const u128 inverse = ((~u128{0} >> 1) / static_cast<u128>(r)) << 29;
    const u128 expected = (pi_q124 >> 1) - inverse;
    const u128 bound = (u128{1} << 52) + (u128{1} << 30);
    EXPECT_TRUE(rounds(atan(raw(r)), expected, bound)) << "x raw = " << r;
    EXPECT_TRUE(rounds(atan(raw(-r)), expected, bound, true)) << "x raw = " << -r;
  }
  // |min| = 2^31 exactly: 1/x = 2^-31 (2^93 units) is exact.
  EXPECT_TRUE(rounds(atan(Fixed::min()), (pi_q124 >> 1) - (u128{1} << 93), u128{1} << 52, true));
}

// atan(m / n) for 1 <= m <= n <= 15 in units of 2^-124, below the exact value by less than 2^18
// units. Euler's series, all terms positive: with y = m^2 / (m^2 + n^2) <= 1/2,
// atan(m / n) = sum_k a_k, a_0 = m n / (m^2 + n^2), a_(k+1) = a_k y (2k + 2) / (2k + 3).
// Terms are kept in units of 2^-116 so that a_k (2k + 2) and a_k m^2 fit in 128 bits; each step
// truncates by less than 3 units, and the terms at least halve, so fewer than 130 are non-zero.
u128 atan_of_ratio(unsigned m, unsigned n) {
  const u128 sum_of_squares = m * m + n * n;
  u128 term = (u128{m * n} << 116) / sum_of_squares;
  u128 sum = 0;
  for (u128 k = 0; term != 0; ++k) {
    sum += term;
    term = term * (2 * k + 2) / (2 * k + 3) * (m * m) / sum_of_squares;
  }
  return sum << 8;
}

TEST(InverseTrig, AtanOfSmallRationalsMatchesEulersSeries) {
  const u128 bound = u128{1} << 18;
  for (unsigned m = 1; m <= 15; ++m) {
    for (unsigned n = 1; n <= 15; ++n) {
      // The first-quadrant angle of (n, m), then its mirror images in the other quadrants.
      const u128 angle = m <= n ? atan_of_ratio(m, n) : (pi_q124 >> 1) - atan_of_ratio(n, m);
      for (const std::int64_t scale : {std::int64_t{1}, one_raw / 16 + 3, one_raw, one_raw << 20}) {
        const Fixed y = raw(m * scale);
        const Fixed x = raw(n * scale);
        EXPECT_TRUE(rounds(atan2(y, x), angle, bound)) << m << " / " << n << " * " << scale;
        EXPECT_TRUE(rounds(atan2(-y, x), angle, bound, true)) << m << " / " << n;
        EXPECT_TRUE(rounds(atan2(y, -x), pi_q124 - angle, bound + 1)) << m << " / " << n;
        EXPECT_TRUE(rounds(atan2(-y, -x), pi_q124 - angle, bound + 1, true)) << m << " / " << n;
      }
      if ((16 % n) == 0) {  // m / n is a dyadic rational, exact in Q32.32
        const Fixed x = raw(static_cast<std::int64_t>(m) * (one_raw / n));
        EXPECT_TRUE(rounds(atan(x), angle, bound)) << m << " / " << n;
        EXPECT_TRUE(rounds(atan(-x), angle, bound, true)) << m << " / " << n;
      }
    }
  }
}

// floor(sqrt(v)) for a 128-bit v, bit by bit.
u128 isqrt(u128 v) {
  u128 root = 0;
  for (int bit = 63; bit >= 0; --bit) {
    const u128 trial = root | (u128{1} << bit);
    if (trial * trial <= v) root = trial;
  }
  return root;
}

TEST(InverseTrig, AcosAndAsinNearOne) {
  // acos(1 - e) = sqrt(2e) (1 + e/12 + 3 e^2 / 160 + ...) with e = k 2^-32. For k <= 2^12 the
  // e^2 term and beyond stay below 2^-55 (2^69 units of 2^-124), inside the bound used below.
  // sqrt(2e) 2^124 = sqrt(2k) 2^108.
  const u128 bound = u128{1} << 70;
  for (std::int64_t k = 1; k <= 4096; ++k) {
    const u128 root = isqrt(static_cast<u128>(2 * k) << 96) << 60;  // within 2^60 units, below
    const u128 acos_value = root + root / 12 * static_cast<u128>(k) / (u128{1} << 32);
    const Fixed x = raw(one_raw - k);
    EXPECT_TRUE(rounds(acos(x), acos_value, bound)) << "k = " << k;
    // acos(-x) = pi - acos(x), asin(x) = pi/2 - acos(x).
    EXPECT_TRUE(rounds(acos(-x), pi_q124 - acos_value, bound)) << "k = " << k;
    EXPECT_TRUE(rounds(asin(x), (pi_q124 >> 1) - acos_value, bound)) << "k = " << k;
    EXPECT_TRUE(rounds(asin(-x), (pi_q124 >> 1) - acos_value, bound, true)) << "k = " << k;
  }
}

// ---- Symmetries --------------------------------------------------------------------------------

std::vector<std::int64_t> sample_raws(std::uint64_t seed, int count) {
  std::mt19937_64 gen(seed);
  std::vector<std::int64_t> out;
  for (int i = 0; i < count; ++i) {
    // Log-uniform magnitudes below 2^63, so that negating them is defined.
    const auto bits = static_cast<std::int64_t>(gen() >> (1 + gen() % 63));
    out.push_back((gen() & 1U) != 0 ? bits : -bits);
  }
  return out;
}

TEST(InverseTrig, AtanAndAsinAreOddExactly) {
  for (const std::int64_t r : sample_raws(1, 200000)) {
    if (r == INT64_MIN) continue;  // -min() saturates to max()
    ASSERT_EQ(atan(raw(-r)), -atan(raw(r))) << r;
    const std::int64_t u = r % (one_raw + 1);  // inside [-1, 1]
    ASSERT_EQ(asin(raw(-u)), -asin(raw(u))) << u;
  }
}

TEST(InverseTrig, AcosOfNegatedArgument) {
  // acos(-x) = pi - acos(x) exactly; each result is off by < 0.5 + 2^-16 ulp and pi() by <= 0.5,
  // so the two sides differ by less than 1.5 + 2^-15 ulp: at most 1 raw step.
  for (const std::int64_t r : sample_raws(2, 200000)) {
    const std::int64_t u = r % (one_raw + 1);
    const std::int64_t diff = acos(raw(-u)).raw() - (Fixed::pi() - acos(raw(u))).raw();
    ASSERT_LE(diff, 1) << u;
    ASSERT_GE(diff, -1) << u;
  }
}

TEST(InverseTrig, Atan2IsAntisymmetricInYExactly) {
  const std::vector<std::int64_t> ys = sample_raws(3, 100000);
  const std::vector<std::int64_t> xs = sample_raws(4, 100000);
  for (std::size_t i = 0; i < ys.size(); ++i) {
    if (ys[i] == 0 || ys[i] == INT64_MIN) continue;  // atan2(0, x < 0) is pi, not -pi
    ASSERT_EQ(atan2(raw(-ys[i]), raw(xs[i])), -atan2(raw(ys[i]), raw(xs[i])))
        << ys[i] << ", " << xs[i];
  }
}

TEST(InverseTrig, Atan2IsInvariantUnderScaling) {
  // atan2(2^k y, 2^k x) has the same exact value, so both faithfully rounded results are floor or
  // ceil of it: at most 1 raw step apart (in practice the exact quotient makes them equal).
  std::mt19937_64 gen(5);
  for (int i = 0; i < 100000; ++i) {
    const auto y = static_cast<std::int64_t>(gen() >> 34) - (std::int64_t{1} << 29);
    const auto x = static_cast<std::int64_t>(gen() >> 34) - (std::int64_t{1} << 29);
    if (y == 0) continue;
    const int k = static_cast<int>(gen() % 33);
    const std::int64_t diff = atan2(raw(y) << k, raw(x) << k).raw() - atan2(raw(y), raw(x)).raw();
    ASSERT_LE(diff < 0 ? -diff : diff, 1) << y << ", " << x << ", k = " << k;
  }
}

TEST(InverseTrig, Atan2AgreesWithAtanOfTheQuotient) {
  // For x > 0, atan2(y, x) = atan(y / x). The quotient is rounded (<= 2^-33 off, and atan' <= 1),
  // and each function is off by < 0.5 + 2^-16 ulp: total < 1.5 + 2^-15 ulp, at most 1 raw step.
  const std::vector<std::int64_t> ys = sample_raws(6, 100000);
  const std::vector<std::int64_t> xs = sample_raws(7, 100000);
  for (std::size_t i = 0; i < ys.size(); ++i) {
    const Fixed y = raw(ys[i]);
    const Fixed x = abs(raw(xs[i]));
    if (x == Fixed::zero()) continue;
    const Fixed q = y / x;
    if (q == Fixed::max() || q == Fixed::min()) continue;  // saturated quotient
    const std::int64_t diff = atan2(y, x).raw() - atan(q).raw();
    ASSERT_LE(diff < 0 ? -diff : diff, 1) << y.raw() << ", " << x.raw();
  }
}

TEST(InverseTrig, Atan2LandsInTheRightQuadrant) {
  const std::vector<std::int64_t> ys = sample_raws(8, 100000);
  const std::vector<std::int64_t> xs = sample_raws(9, 100000);
  for (std::size_t i = 0; i < ys.size(); ++i) {
    const Fixed y = raw(ys[i]);
    const Fixed x = raw(xs[i]);
    if (y == Fixed::zero() || x == Fixed::zero()) continue;
    const Fixed a = atan2(y, x);
    if (y > Fixed::zero()) {
      ASSERT_TRUE(x > Fixed::zero() ? (a >= Fixed::zero() && a <= Fixed::half_pi())
                                    : (a >= Fixed::half_pi() && a <= Fixed::pi()))
          << y.raw() << ", " << x.raw() << " -> " << a.raw();
    } else {
      ASSERT_TRUE(x > Fixed::zero() ? (a <= Fixed::zero() && a >= -Fixed::half_pi())
                                    : (a <= -Fixed::half_pi() && a >= -Fixed::pi()))
          << y.raw() << ", " << x.raw() << " -> " << a.raw();
    }
  }
}

// ---- Monotonicity ------------------------------------------------------------------------------

// Checks that f is non-decreasing (sign = 1) or non-increasing (sign = -1) over `count` consecutive
// raw values from `start` in steps of `step`.
template <class F>
void expect_monotone(F f, std::int64_t start, std::int64_t step, std::int64_t count, int sign) {
  Fixed previous = f(raw(start));
  for (std::int64_t i = 1; i < count; ++i) {
    // Unsigned arithmetic: the sweeps over the whole range pass through sums above INT64_MAX.
    const auto r =
        static_cast<std::int64_t>(static_cast<std::uint64_t>(start) +
                                  static_cast<std::uint64_t>(i) * static_cast<std::uint64_t>(step));
    const Fixed current = f(raw(r));
    ASSERT_TRUE(sign > 0 ? previous <= current : previous >= current)
        << "at raw " << r << ": " << ::testing::PrintToString(previous) << " then "
        << ::testing::PrintToString(current);
    previous = current;
  }
}

TEST(InverseTrig, AtanIsMonotone) {
  const auto f = [](Fixed x) { return atan(x); };
  for (std::int64_t j = -64; j <= 64; ++j) {  // around every segment start of [-1, 1]
    expect_monotone(f, j * (one_raw / 64) - 2000, 1, 4000, 1);
  }
  for (const std::int64_t centre :
       {2 * one_raw, 64 * one_raw / 3, 1000 * one_raw, std::int64_t{1} << 50, INT64_MAX - 5000}) {
    expect_monotone(f, centre - 5000, 1, 5000, 1);
    expect_monotone(f, -centre - 5000, 1, 5000, 1);
  }
  expect_monotone(f, INT64_MIN, (std::int64_t{1} << 45) + 12345, 500000, 1);  // whole range
  expect_monotone(f, -4 * one_raw, 8191, 2 * 4 * one_raw / 8191, 1);
}

TEST(InverseTrig, AsinAndAcosAreMonotone) {
  const auto fs = [](Fixed x) { return asin(x); };
  const auto fc = [](Fixed x) { return acos(x); };
  for (const std::int64_t centre : {std::int64_t{0}, one_raw / 2, one_raw / 4, 3 * one_raw / 4,
                                    one_raw - 3000, -one_raw / 2, -one_raw + 3000}) {
    expect_monotone(fs, centre - 3000, 1, 6000, 1);
    expect_monotone(fc, centre - 3000, 1, 6000, -1);
  }
  expect_monotone(fs, -one_raw - 10, 4093, 2 * one_raw / 4093 + 10, 1);
  expect_monotone(fc, -one_raw - 10, 4093, 2 * one_raw / 4093 + 10, -1);
}

TEST(InverseTrig, ResultsStayInRange) {
  for (const std::int64_t r : sample_raws(10, 100000)) {
    const Fixed a = atan(raw(r));
    ASSERT_TRUE(a >= -Fixed::half_pi() && a <= Fixed::half_pi()) << r;
    const Fixed s = asin(raw(r));
    ASSERT_TRUE(s >= -Fixed::half_pi() && s <= Fixed::half_pi()) << r;
    const Fixed c = acos(raw(r));
    ASSERT_TRUE(c >= Fixed::zero() && c <= Fixed::pi()) << r;
    const Fixed t = atan2(raw(r), raw(r ^ 0x5A5A5A5A5A5A5A5A));
    ASSERT_TRUE(t >= -Fixed::pi() && t <= Fixed::pi()) << r;
  }
}

}  // namespace
}  // namespace detsim

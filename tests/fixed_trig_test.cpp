// sin, cos, sincos and tan: exact values, symmetries, identities, monotonicity, the unit-circle
// guarantee of sincos and saturation of tan at its poles.
//
// Expected values are derived here without the implementation: from exact symmetries, from Taylor
// series with bounded remainders, from the published hexadecimal expansion of pi, and from
// identities whose error is bounded by the accuracy claim of math.hpp. The claim under test: sin
// and cos are within 0.5 + 2^-26 ulp of the exact value (faithful: each result is the exact value
// rounded down or up), sincos components are faithful, tan is faithful where |tan| < 2^16 and
// saturates where the exact value is beyond the range. In the derivations below S, C, T are raw
// results, s, c, t the exact values times 2^32, and S = s + a, C = c + b with |a|, |b| < 1.
#include <algorithm>
#include <cstdint>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <detsim/fixed/math.hpp>

#include "support/print.hpp"

namespace detsim {
namespace {

__extension__ using u128 = unsigned __int128;
__extension__ using i128 = __int128;

constexpr std::int64_t one_raw = std::int64_t{1} << 32;
constexpr std::int64_t raw_max = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t raw_min = std::numeric_limits<std::int64_t>::min();

Fixed raw(std::int64_t r) {
  return Fixed::from_raw(r);
}

std::string show(Fixed x) {
  return ::testing::PrintToString(x);
}

// floor(pi * 2^124): the first 32 hexadecimal digits of pi, 3.243F6A8885A308D313198A2E0370734...
// (the same digits that seed Blowfish's P-array). Error < 2^-124.
constexpr u128 pi_q124 = (u128{0x3243F6A8885A308DU} << 64) | u128{0x313198A2E0370734U};

// floor(k pi/2 2^32), the raw value just below k pi/2, for 0 <= k < 2^31 with k pi/2 < 2^31.
// k pi/2 2^32 = k pi_q124 / 2^93, split so that nothing overflows 128 bits. The truncation of pi
// moves the product by less than 2^-62 raw units, far less than the distance of any k pi/2 2^32
// (k < 2^31) from an integer (> 2^-35, from the continued fraction of 1/(pi 2^31)), so the floor
// is exact.
std::int64_t raw_below_multiple_of_half_pi(std::uint64_t k) {
  const u128 high = k * (pi_q124 >> 64);  // < 2^93
  const u128 low = k * (pi_q124 & ~std::uint64_t{0});
  const u128 carry_part = ((high & ((u128{1} << 29) - 1)) << 64) + low;  // < 2^96
  return static_cast<std::int64_t>((high >> 29) + (carry_part >> 93));
}

// Largest k with k pi/2 < 2^31: floor(2^31 / (pi/2)) = floor(2^32 / pi) = 1367130551.
constexpr std::uint64_t largest_quarter_turn = 1367130551;

// Inputs: uniform over all raws, and log-uniform magnitudes (so small arguments and every scale
// are common), both signs.
std::vector<std::int64_t> random_raws(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::int64_t> v;
  v.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t bits = rng();
    if (i % 2 == 0) {
      v.push_back(static_cast<std::int64_t>(bits));
    } else {
      const unsigned width = static_cast<unsigned>(rng() % 64);
      const std::uint64_t mag = width == 0 ? 0 : bits >> (64 - width);
      v.push_back((rng() & 1U) != 0 ? -static_cast<std::int64_t>(mag)
                                    : static_cast<std::int64_t>(mag));
    }
  }
  return v;
}

// Inputs near multiples of pi/4 and pi/2 (where the kernel arguments are extreme), near 0 and at
// the ends of the range, plus the inputs nearest to multiples of pi/2 over the whole range: the
// continued-fraction convergents of 1/(pi 2^31) give the quarter-turn counts k of the closest
// approaches (raw 0x26824063C13CB0B5 is 2^-34.2 raw units from 411301173 pi/2).
std::vector<std::int64_t> edge_raws() {
  std::vector<std::int64_t> v = {0,        1,       -1,      2,           -2,         one_raw,
                                 -one_raw, raw_max, raw_min, raw_min + 1, raw_max - 1};
  const std::uint64_t closest_k[] = {263205,  818204,  1081409,   4062431,
                                     5143840, 9206271, 134031634, 411301173};
  std::vector<std::uint64_t> ks(std::begin(closest_k), std::end(closest_k));
  for (std::uint64_t k = 0; k < 64; ++k)
    ks.push_back(k);
  for (std::uint64_t k = largest_quarter_turn - 8; k <= largest_quarter_turn; ++k)
    ks.push_back(k);
  for (const std::uint64_t k : ks) {
    // k pi/2 and (2k + 1) pi/4 (between k pi/2 and (k + 1) pi/2; below 2^31 when k + 1 is).
    const std::int64_t at = raw_below_multiple_of_half_pi(k);
    std::vector<std::int64_t> centres = {at};
    if (k < largest_quarter_turn)
      centres.push_back(at / 2 + raw_below_multiple_of_half_pi(k + 1) / 2);
    for (const std::int64_t centre : centres) {
      for (std::int64_t d = -3; d <= 3; ++d) {
        if (centre + d < 0) continue;
        v.push_back(centre + d);
        v.push_back(-(centre + d));
      }
    }
  }
  return v;
}

std::vector<std::int64_t> all_inputs() {
  std::vector<std::int64_t> v = edge_raws();
  const std::vector<std::int64_t> r = random_raws(200000, 0x7219);
  v.insert(v.end(), r.begin(), r.end());
  return v;
}

i128 square(std::int64_t r) {
  return i128{r} * r;
}

i128 abs128(i128 v) {
  return v < 0 ? -v : v;
}

TEST(FixedTrig, ExactAtZero) {
  EXPECT_EQ(sin(Fixed::zero()), Fixed::zero());
  EXPECT_EQ(cos(Fixed::zero()), Fixed::one());
  EXPECT_EQ(tan(Fixed::zero()), Fixed::zero());
  EXPECT_EQ(sincos(Fixed::zero()).sin, Fixed::zero());
  EXPECT_EQ(sincos(Fixed::zero()).cos, Fixed::one());
}

// For 0 < x: x - x^3/6 < sin x < x, 1 - x^2/2 < cos x < 1 and x < tan x < x + x^3/2 (x < 1/2).
// Below the bounds used here each error term is under one ulp, so the faithful results are pinned
// to the two raws around the exact value.
TEST(FixedTrig, SmallArgumentsFollowTaylorBounds) {
  std::vector<std::int64_t> xs = {1, 2, 3, 1000, 0xFFFFF, 0x100000};
  std::mt19937_64 rng(11);
  for (int i = 0; i < 2000; ++i)
    xs.push_back(static_cast<std::int64_t>(rng() >> 44));  // < 2^20
  for (const std::int64_t r : xs) {
    // x^3/6 < 2^-32 and x^3/2 < 2^-32 for x <= 2^-12 (raw <= 2^20).
    const Fixed x = raw(r);
    EXPECT_TRUE(sin(x).raw() == r || sin(x).raw() == r - 1) << show(x) << " -> " << show(sin(x));
    EXPECT_TRUE(tan(x).raw() == r || tan(x).raw() == r + 1) << show(x) << " -> " << show(tan(x));
    EXPECT_EQ(sin(-x), -sin(x));
    // sincos keeps both components faithful: the same pins (here cos is rounded up whenever it
    // is 1, and sin whenever it is x, so these catch a lowering of the wrong component).
    const SinCos p = sincos(x);
    EXPECT_TRUE(p.sin.raw() == r || p.sin.raw() == r - 1) << show(x) << " -> " << show(p.sin);
    // x^2/2 < 2^-32 for x < 2^-15.5; cos x in (1 - 2^-32, 1): 1 or 1 - ulp.
    if (r < (std::int64_t{1} << 16)) {
      EXPECT_TRUE(cos(x).raw() == one_raw || cos(x).raw() == one_raw - 1) << show(x);
      EXPECT_TRUE(p.cos.raw() == one_raw || p.cos.raw() == one_raw - 1) << show(x);
    }
  }
}

// For 0 < x <= 2^-8 (raw r <= 2^24), two Taylor terms pin each function within a sliver of an ulp:
//   sin x 2^32 in (r - r^3 / (6 2^64), r - r^3 / (6 2^64) + 2^-14)           (next term x^5/120)
//   cos x 2^32 in (2^32 - E / (3 2^99) - 2^-25, 2^32 - E / (3 2^99)),  E = 3 2^66 r^2 - r^4
// (next term x^6/720), exact rationals in 128 bits. Where the interval holds no integer, the
// faithful results are its floor and floor + 1: sin, cos and both sincos components must be one
// of them (so sincos must not lower a component that was rounded down).
TEST(FixedTrig, SmallArgumentsAreFaithfulToTheirTaylorPolynomials) {
  std::mt19937_64 rng(21);
  std::size_t checked = 0;
  for (int i = 0; i < 200000; ++i) {
    const std::uint64_t r = 1 + rng() % (std::uint64_t{1} << 24);
    const Fixed x = raw(static_cast<std::int64_t>(r));
    const SinCos p = sincos(x);
    const auto faithful = [](Fixed got, std::int64_t floor_raw) {
      return got.raw() == floor_raw || got.raw() == floor_raw + 1;
    };
    const u128 sin_den = u128{6} << 64;
    const u128 cubed = u128{r} * r * r;
    const u128 sin_rem = cubed % sin_den;
    // Interval (r - q - 1 + (1 - rem / den), that + 2^-14): no integer inside unless rem is tiny.
    if (sin_rem > (sin_den >> 14)) {
      const auto floor_raw =
          static_cast<std::int64_t>(r - static_cast<std::uint64_t>(cubed / sin_den) - 1);
      ASSERT_TRUE(faithful(sin(x), floor_raw)) << show(x) << " sin " << show(sin(x));
      ASSERT_TRUE(faithful(p.sin, floor_raw)) << show(x) << " sincos.sin " << show(p.sin);
      ++checked;
    }
    const u128 cos_den = u128{3} << 99;
    const u128 e = (u128{3} << 66) * r * r - u128{r} * r * r * r;
    const u128 cos_rem = e % cos_den;
    // 2^32 - e / den = 2^32 - q - 1 + (1 - rem / den); the interval reaches 2^-25 below that.
    if (cos_rem != 0 && cos_rem < cos_den - (cos_den >> 25)) {
      const auto floor_raw = one_raw - static_cast<std::int64_t>(e / cos_den) - 1;
      ASSERT_TRUE(faithful(cos(x), floor_raw)) << show(x) << " cos " << show(cos(x));
      ASSERT_TRUE(faithful(p.cos, floor_raw)) << show(x) << " sincos.cos " << show(p.cos);
      ++checked;
    }
  }
  EXPECT_GT(checked, std::size_t{390000});
}

TEST(FixedTrig, SinIsOddAndCosIsEvenBitForBit) {
  for (const std::int64_t r : all_inputs()) {
    if (r == raw_min) continue;  // -min() saturates to max(), a different argument
    const Fixed x = raw(r);
    ASSERT_EQ(sin(-x), -sin(x)) << show(x);
    ASSERT_EQ(cos(-x), cos(x)) << show(x);
    const SinCos p = sincos(x);
    const SinCos n = sincos(-x);
    ASSERT_EQ(n.sin, -p.sin) << show(x);
    ASSERT_EQ(n.cos, p.cos) << show(x);
  }
}

TEST(FixedTrig, TanIsOddWhereNotSaturated) {
  for (const std::int64_t r : all_inputs()) {
    if (r == raw_min) continue;
    const Fixed x = raw(r);
    const Fixed t = tan(x);
    if (t == Fixed::max()) {
      // max() is the saturated value or the rounded magnitude 2^31 - ulp, whose negation is
      // -max(); the opposite argument gives that or saturates to min().
      EXPECT_TRUE(tan(-x) == Fixed::min() || tan(-x) == -Fixed::max()) << show(x);
      continue;
    }
    ASSERT_EQ(tan(-x), -t) << show(x);
  }
}

TEST(FixedTrig, ResultsStayWithinTheUnitInterval) {
  for (const std::int64_t r : all_inputs()) {
    const Fixed x = raw(r);
    ASSERT_LE(abs(sin(x)), Fixed::one()) << show(x);
    ASSERT_LE(abs(cos(x)), Fixed::one()) << show(x);
  }
}

// S^2 + C^2 - 2^64 = 2(s a + c b) + a^2 + b^2, so |S^2 + C^2 - 2^64| < 2(|s| + |c|) + 2
// <= 2(|S| + |C|) + 6 for faithful S and C.
TEST(FixedTrig, PythagoreanIdentityWithinFaithfulBound) {
  for (const std::int64_t r : all_inputs()) {
    const Fixed x = raw(r);
    const std::int64_t s = sin(x).raw();
    const std::int64_t c = cos(x).raw();
    const i128 excess = square(s) + square(c) - (i128{1} << 64);
    const i128 bound = 2 * (abs128(s) + abs128(c)) + 6;
    ASSERT_LT(abs128(excess), bound)
        << show(x) << " sin " << show(sin(x)) << " cos " << show(cos(x));
  }
}

TEST(FixedTrig, SinCosStaysInsideTheUnitCircle) {
  for (const std::int64_t r : all_inputs()) {
    const Fixed x = raw(r);
    const SinCos p = sincos(x);
    ASSERT_LE(square(p.sin.raw()) + square(p.cos.raw()), i128{1} << 64)
        << show(x) << " sin " << show(p.sin) << " cos " << show(p.cos);
  }
}

// One step toward zero, or none.
bool same_or_one_toward_zero(Fixed pair_value, Fixed alone) {
  const std::int64_t a = alone.raw();
  const std::int64_t p = pair_value.raw();
  return p == a || (a > 0 && p == a - 1) || (a < 0 && p == a + 1);
}

// math.hpp: sincos is (sin, cos) unless that pair leaves the unit circle; then components are
// lowered one ulp toward zero, which keeps them faithful and brings the pair inside.
TEST(FixedTrig, SinCosIsSinAndCosUnlessThePairLeavesTheCircle) {
  std::size_t adjusted = 0;
  const std::vector<std::int64_t> inputs = all_inputs();
  for (const std::int64_t r : inputs) {
    const Fixed x = raw(r);
    const Fixed s = sin(x);
    const Fixed c = cos(x);
    const SinCos p = sincos(x);
    const bool outside = square(s.raw()) + square(c.raw()) > (i128{1} << 64);
    if (!outside) {
      ASSERT_EQ(p.sin, s) << show(x);
      ASSERT_EQ(p.cos, c) << show(x);
      continue;
    }
    ++adjusted;
    ASSERT_TRUE(same_or_one_toward_zero(p.sin, s)) << show(x) << show(p.sin) << show(s);
    ASSERT_TRUE(same_or_one_toward_zero(p.cos, c)) << show(x) << show(p.cos) << show(c);
    ASSERT_TRUE(p.sin != s || p.cos != c) << show(x);
  }
  // Rounding both to nearest leaves the circle for roughly half of all arguments; the test must
  // have exercised the adjustment.
  EXPECT_GT(adjusted, inputs.size() / 10);
}

// half_pi() is pi/2 + d with |d| <= 2^-33 (correctly rounded, fixed.hpp), and h - x is exact for
// |x| < 2^30. |sin x - cos(pi/2 - x + d)| <= |d|, so |S - C'| < 1 + 0.5 + 1 raw units: <= 2.
// Likewise sin(x + pi()) = -sin x within 2 raw units, and cos(x + pi()) = -cos x.
TEST(FixedTrig, ComplementAndHalfTurnIdentitiesWithinDerivedTolerance) {
  std::mt19937_64 rng(5);
  for (int i = 0; i < 200000; ++i) {
    const auto r = static_cast<std::int64_t>(rng() >> 2) - (std::int64_t{1} << 61);  // |x| < 2^29
    const Fixed x = raw(r);
    const std::int64_t d1 = sin(x).raw() - cos(Fixed::half_pi() - x).raw();
    ASSERT_LE(d1 < 0 ? -d1 : d1, 2) << show(x);
    const std::int64_t d2 = sin(x).raw() + sin(x + Fixed::pi()).raw();
    ASSERT_LE(d2 < 0 ? -d2 : d2, 2) << show(x);
    const std::int64_t d3 = cos(x).raw() + cos(x + Fixed::pi()).raw();
    ASSERT_LE(d3 < 0 ? -d3 : d3, 2) << show(x);
  }
}

// sin 2x = 2 s c: 2SC - 2sc = 2(s b + c a + a b), |.| < 2(|s| + |c| + 1) <= 2(|S| + |C| + 3) and
// the faithful S2 adds < 2^32 (units of 2^-64). cos 2x = c^2 - s^2: |C^2 - S^2 - (c^2 - s^2)| <
// 2(|S| + |C| + 2) + 2. x + x is exact for |x| < 2^30.
TEST(FixedTrig, DoubleAngleIdentitiesWithinDerivedTolerance) {
  std::vector<std::int64_t> xs = random_raws(200000, 77);
  for (std::int64_t& r : xs)
    r /= 4;  // |x| < 2^29
  for (const std::int64_t r : xs) {
    const Fixed x = raw(r);
    const std::int64_t s = sin(x).raw();
    const std::int64_t c = cos(x).raw();
    const i128 s2 = i128{sin(x + x).raw()} << 32;
    const i128 c2 = i128{cos(x + x).raw()} << 32;
    const i128 sin_bound = (i128{1} << 32) + 2 * (abs128(s) + abs128(c) + 3);
    const i128 cos_bound = (i128{1} << 32) + 2 * (abs128(s) + abs128(c) + 2) + 2;
    ASSERT_LT(abs128(s2 - 2 * i128{s} * c), sin_bound) << show(x);
    ASSERT_LT(abs128(c2 - (square(c) - square(s))), cos_bound) << show(x);
  }
}

// With an error below 0.5 + 2^-26 ulp, a decrease between x1 < x2 needs sin x2 - sin x1 < 2^-25
// ulp, i.e. cos x2 < 2^-25 (one raw step moves sin by cos x ulp). That is only within 2^-25 of
// +-pi/2, where |sin| > 1 - 2^-51 is nowhere near a rounding tie, so sin is nondecreasing on
// [-pi/2, pi/2], and cos nonincreasing on [0, pi] (the same kernel).
TEST(FixedTrig, SinIsMonotonicOnTheCentralInterval) {
  constexpr std::int64_t h = Fixed::half_pi().raw();  // below pi/2 2^32 (see the saturation test)
  std::vector<std::int64_t> xs;
  std::mt19937_64 rng(3);
  const std::int64_t step = (2 * h) >> 19;
  for (std::int64_t r = -h; r <= h - step; r += step) {
    xs.push_back(r + static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(step)));
  }
  for (const std::int64_t centre : {-h, std::int64_t{0}, h}) {
    for (std::int64_t r = centre - 20000; r <= centre + 20000; ++r) {
      if (r >= -h && r <= h) xs.push_back(r);
    }
  }
  std::sort(xs.begin(), xs.end());
  // The first consecutive pair out of order, if any (one assertion, not one per pair).
  const auto first_decrease = [&](auto f, bool increasing) -> std::size_t {
    for (std::size_t i = 1; i < xs.size(); ++i) {
      const Fixed a = f(raw(xs[i - 1]));
      const Fixed b = f(raw(xs[i]));
      if (increasing ? b < a : a < b) return i;
    }
    return 0;
  };
  const std::size_t bad_sin = first_decrease([](Fixed x) { return sin(x); }, true);
  EXPECT_EQ(bad_sin, 0U) << "sin decreases from " << show(raw(xs[bad_sin == 0 ? 0 : bad_sin - 1]))
                         << " to " << show(raw(xs[bad_sin]));
  // cos on [0, pi]: the same sweep shifted by h.
  const std::size_t bad_cos = first_decrease([](Fixed x) { return cos(x + raw(h)); }, false);
  EXPECT_EQ(bad_cos, 0U) << "cos increases from "
                         << show(raw(xs[bad_cos == 0 ? 0 : bad_cos - 1] + h)) << " to "
                         << show(raw(xs[bad_cos] + h));
}

// tan = s / c. With T = t + d (|d| < 1, |tan| < 2^16): T C - S 2^32 = -a 2^32 + t b 2^32 + d C
// (units of 2^-64), so |T C - S 2^32| < 2^32 (1 + (|S| + 1) / (|C| - 1)) + |C|. Checked away from
// the poles, where |cos| >= 2^-8.
TEST(FixedTrig, TanMatchesSinOverCosWithinDerivedTolerance) {
  std::size_t checked = 0;
  for (const std::int64_t r : all_inputs()) {
    const Fixed x = raw(r);
    const std::int64_t s = sin(x).raw();
    const std::int64_t c = cos(x).raw();
    if (abs128(c) < (i128{1} << 24)) continue;
    ++checked;
    const i128 t = tan(x).raw();
    const i128 lhs = abs128(t * c - (i128{s} << 32));
    const i128 ratio =
        ((i128{1} << 32) * (abs128(s) + 1) + abs128(c) - 2) / (abs128(c) - 1);  // ceil
    ASSERT_LT(lhs, (i128{1} << 32) + ratio + abs128(c))
        << show(x) << " tan " << show(tan(x)) << " sin " << show(sin(x)) << " cos " << show(cos(x));
  }
  EXPECT_GT(checked, std::size_t{100000});
}

// 3.14159265358979 < pi < 3.14159265358980, so half_pi() = 0x1921FB544 lies below pi/2 2^32 and
// half_pi() + ulp above: 2 h 10^14 < 314159265358979 2^32 < 314159265358980 2^32 < 2 (h + 1) 10^14.
TEST(FixedTrig, HalfPiRawNeighboursStraddlePiOverTwo) {
  const i128 h = Fixed::half_pi().raw();
  const i128 e14 = 100000000000000;
  EXPECT_LT(2 * h * e14, i128{314159265358979} << 32);
  EXPECT_GT(2 * (h + 1) * e14, i128{314159265358980} << 32);
  EXPECT_EQ(raw_below_multiple_of_half_pi(1), Fixed::half_pi().raw());
}

// For odd k, x = r below k pi/2 by e in (0, 2^-32) has tan x = cot e > 1/e - e > 2^32 - 1 > 2^31:
// beyond the range, saturated to max(). The next raw, above k pi/2 by less than 2^-32, has
// tan x < -2^31: min(). Two raws further out, |tan| > 2^31 (1 - 2^-60) still: with the contract's
// relative error < 2^-46 the result stays above 2^30 in magnitude with the same sign.
// sin and cos there: |cos| < sin e < 2^-32, so cos is 0 or +-ulp and |sin| is 1 or 1 - ulp; for
// even k the roles swap. Signs: sin(k pi/2 - e) has the sign of sin(k pi/2) (odd k) or of
// -cos(k pi/2) (even k).
TEST(FixedTrig, BehaviourAtTheRawNeighboursOfMultiplesOfHalfPi) {
  std::vector<std::uint64_t> ks = {1,
                                   2,
                                   3,
                                   4,
                                   5,
                                   263205,
                                   818204,
                                   1081409,
                                   4062431,
                                   5143840,
                                   9206271,
                                   134031634,
                                   411301173,
                                   largest_quarter_turn,
                                   largest_quarter_turn - 1};
  std::mt19937_64 rng(9);
  for (int i = 0; i < 20000; ++i)
    ks.push_back(rng() % (largest_quarter_turn + 1));
  for (const std::uint64_t k : ks) {
    const std::int64_t below = raw_below_multiple_of_half_pi(k);
    const Fixed x0 = raw(below);
    const Fixed x1 = raw(below + 1);
    const std::int64_t sign = (k / 2) % 2 == 0 ? 1 : -1;  // sign of sin / cos at k pi/2
    if (k % 2 == 1) {
      ASSERT_EQ(tan(x0), Fixed::max()) << "k=" << k << " " << show(x0);
      ASSERT_EQ(tan(x1), Fixed::min()) << "k=" << k << " " << show(x1);
      ASSERT_GT(tan(raw(below - 1)), Fixed::from_int(1 << 30)) << "k=" << k;
      ASSERT_LT(tan(raw(below + 2)), -Fixed::from_int(1 << 30)) << "k=" << k;
      for (const Fixed x : {x0, x1}) {
        ASSERT_LE(abs(cos(x)), Fixed::epsilon()) << "k=" << k << " " << show(x);
        ASSERT_GE(sign * sin(x).raw(), one_raw - 1) << "k=" << k << " " << show(x);
      }
      // cos(k pi/2 - e) = sign sin(e) for odd k (k = 1: cos(pi/2 - e) = sin e > 0).
      ASSERT_GE(sign * cos(x0).raw(), 0) << "k=" << k;
      ASSERT_LE(sign * cos(x1).raw(), 0) << "k=" << k;
    } else {
      for (const Fixed x : {x0, x1}) {
        ASSERT_LE(abs(sin(x)), Fixed::epsilon()) << "k=" << k << " " << show(x);
        ASSERT_LE(abs(tan(x)), Fixed::epsilon()) << "k=" << k << " " << show(x);
        ASSERT_GE(sign * cos(x).raw(), one_raw - 1) << "k=" << k << " " << show(x);
      }
      // sin(k pi/2 - e) = -sign sin(e) for even k.
      ASSERT_LE(sign * sin(x0).raw(), 0) << "k=" << k;
      ASSERT_GE(sign * sin(x1).raw(), 0) << "k=" << k;
    }
  }
}

}  // namespace
}  // namespace detsim

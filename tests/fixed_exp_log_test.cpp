// exp, exp2, log, log2 and pow. Expected values are derived, never taken from exp_log.cpp: exact
// powers of two, thresholds computed here from ln 2 in 128-bit integer arithmetic, closed forms
// evaluated to 30 digits, identities against independently tested operations (*, /, sqrt), and
// properties (monotonicity, round trips within a bound derived from the contract in math.hpp).
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/math.hpp>
#include <detsim/fixed/wide.hpp>

#include "support/print.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;
using wide::U128;

constexpr std::int64_t kOne = Fixed::one_raw;
constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMin = std::numeric_limits<std::int64_t>::min();

// ln 2 = 0.B17217F7D1CF79AB C9E3B39803F2F6AF... (hexadecimal), as a Q0.128 integer. The test
// LnTwoConstant ties it to Fixed::ln2(), which the constants test checks against MPFR.
constexpr U128 kLn2{0xB17217F7D1CF79ABU, 0xC9E3B39803F2F6AFU};

Fixed raw(std::int64_t r) {
  return Fixed::from_raw(r);
}

std::string show(Fixed x) {
  return ::testing::PrintToString(x);
}

std::uint64_t distance(Fixed a, Fixed b) {
  return a < b ? static_cast<std::uint64_t>(b.raw()) - static_cast<std::uint64_t>(a.raw())
               : static_cast<std::uint64_t>(a.raw()) - static_cast<std::uint64_t>(b.raw());
}

/// k ln2 2^32 = floor + fraction / 2^64, from the 128-bit ln 2 (error < 32 2^-128 2^32, far below
/// the 2^-16 margin every caller asserts on the fraction).
struct Scaled {
  std::int64_t floor;
  std::uint64_t fraction;
};

Scaled k_ln2_raw(std::uint64_t k) {
  // k ln2 2^128 as a 192-bit number; the raw value is that divided by 2^96.
  const U128 low = wide::Portable::mul(k, kLn2.lo);
  const U128 high = wide::Portable::mul(k, kLn2.hi);
  const U128 top = wide::add(high, U128{0, low.hi});  // k ln2 2^64
  return {static_cast<std::int64_t>(wide::shr(top, 32).lo), (top.lo << 32) | (low.lo >> 32)};
}

bool fraction_is_clear(std::uint64_t fraction) {  // at least 2^-16 away from an integer
  constexpr std::uint64_t margin = std::uint64_t{1} << 48;
  return fraction > margin && fraction < 0U - margin;
}

/// The largest error (in raw units) the contract allows around |value| (raw): below 2^16 the
/// result is faithful (one ulp); above, the relative error is below 2^-46.
std::uint64_t contract_ulps(std::int64_t value) {
  const std::uint64_t mag = detail::magnitude(value);
  if (mag < (std::uint64_t{1} << 48)) return 1;
  return (mag >> 46) + 1;
}

std::vector<std::int64_t> random_raws(std::size_t n, std::int64_t lo, std::int64_t hi,
                                      std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::int64_t> dist(lo, hi);
  std::vector<std::int64_t> v(n);
  for (auto& r : v)
    r = dist(rng);
  return v;
}

// ---- Constants and exact values -----------------------------------------------------------------

TEST(FixedExpLog, LnTwoConstant) {
  // round(ln2 2^32) from the 128-bit constant must be the correctly rounded Fixed::ln2().
  const std::uint64_t hi = kLn2.hi;
  const std::uint64_t rounded = (hi >> 32) + ((hi >> 31) & 1U);  // the bits below are not a tie
  EXPECT_EQ(static_cast<std::int64_t>(rounded), Fixed::ln2().raw());
}

TEST(FixedExpLog, Exp2OfIntegersIsExact) {
  for (int k = -32; k <= 30; ++k) {
    const Fixed expected = raw(std::int64_t{1} << (k + 32));
    EXPECT_EQ(exp2(Fixed::from_int(k)), expected) << "k = " << k;
  }
  // 2^-33 is half an ulp exactly: ties to even gives 0. Everything below rounds to 0.
  EXPECT_EQ(exp2(Fixed::from_int(-33)), Fixed::zero());
  for (int k = -34; k >= -200; --k)
    EXPECT_EQ(exp2(Fixed::from_int(k)), Fixed::zero()) << k;
  for (int k = 31; k <= 200; ++k)
    EXPECT_EQ(exp2(Fixed::from_int(k)), Fixed::max()) << k;
}

TEST(FixedExpLog, Log2OfPowersOfTwoIsExact) {
  for (int k = -32; k <= 30; ++k) {
    EXPECT_EQ(log2(raw(std::int64_t{1} << (k + 32))), Fixed::from_int(k)) << "k = " << k;
  }
  // log2(2^31 - 2^-32) = 31 + log2(1 - 2^-63) = 31 - 1.6e-19: rounds to 31.
  EXPECT_EQ(log2(Fixed::max()), Fixed::from_int(31));
}

TEST(FixedExpLog, UnitValues) {
  EXPECT_EQ(exp(Fixed::zero()), Fixed::one());
  EXPECT_EQ(exp2(Fixed::zero()), Fixed::one());
  EXPECT_EQ(log(Fixed::one()), Fixed::zero());
  EXPECT_EQ(log2(Fixed::one()), Fixed::zero());
  EXPECT_EQ(exp2(Fixed::one()), Fixed::from_int(2));
  EXPECT_EQ(exp2(-Fixed::one()), Fixed::half());
  // Faithful: within one ulp of the exact value, and Fixed::e() is the correctly rounded e.
  EXPECT_LE(distance(exp(Fixed::one()), Fixed::e()), 1U) << show(exp(Fixed::one()));
  // log(e()) = 1 + log(e() / e), |e() - e| <= 2^-33, so the exact value is within 0.19 ulp of 1.
  EXPECT_LE(distance(log(Fixed::e()), Fixed::one()), 1U) << show(log(Fixed::e()));
  // exp(ln2()) = 2 e^(ln2() - ln2), |ln2() - ln2| <= 2^-33: exact within 1 ulp of 2.
  EXPECT_LE(distance(exp(Fixed::ln2()), Fixed::from_int(2)), 2U) << show(exp(Fixed::ln2()));
  EXPECT_LE(distance(exp2(Fixed::half()), Fixed::sqrt2()), 1U) << show(exp2(Fixed::half()));
}

TEST(FixedExpLog, LogOfPowersOfTwo) {
  // log(2^k) = k ln2: faithful means one of the two raws around k ln2 2^32.
  for (int k = -32; k <= 30; ++k) {
    if (k == 0) continue;
    const Scaled s = k_ln2_raw(static_cast<std::uint64_t>(k < 0 ? -k : k));
    ASSERT_TRUE(fraction_is_clear(s.fraction)) << k;
    const Fixed got = log(raw(std::int64_t{1} << (k + 32)));
    const std::int64_t lo = k < 0 ? -s.floor - 1 : s.floor;
    EXPECT_TRUE(got.raw() == lo || got.raw() == lo + 1) << "k = " << k << ": " << show(got);
  }
  // log(2^31 - 2^-32) = 31 ln2 - 2^-63 (to 1e-38): still strictly between the same two raws.
  const Scaled s31 = k_ln2_raw(31);
  ASSERT_TRUE(fraction_is_clear(s31.fraction));
  const Fixed top = log(Fixed::max());
  EXPECT_TRUE(top.raw() == s31.floor || top.raw() == s31.floor + 1) << show(top);
}

TEST(FixedExpLog, LogDomain) {
  for (const std::int64_t r : {std::int64_t{0}, std::int64_t{-1}, -kOne, kMin, kMin + 1}) {
    EXPECT_EQ(log(raw(r)), Fixed::min()) << r;
    EXPECT_EQ(log2(raw(r)), Fixed::min()) << r;
  }
  EXPECT_EQ(log2(Fixed::epsilon()), Fixed::from_int(-32));
}

// ---- Saturation and underflow thresholds ------------------------------------------------------

TEST(FixedExpLog, Exp2Thresholds) {
  // 2^(31 - 2^-32) = 2^31 (1 - ln2 2^-32 + ...) > 2^31 - 0.35 is representable (no saturation),
  // and its raw value is at least 2^63 - ln2 2^31 > 2^63 - 0.7 2^31.
  const Fixed below = exp2(raw(31 * kOne - 1));
  EXPECT_NE(below, Fixed::max());
  EXPECT_GE(below.raw(), kMax - (std::int64_t{7} << 31) / 10 - (kMax >> 46)) << show(below);
  EXPECT_EQ(exp2(raw(31 * kOne)), Fixed::max());
  EXPECT_EQ(exp2(Fixed::max()), Fixed::max());
  // 2^-32 is one ulp; 2^(-33 + 2^-32) is just above half an ulp (rounds up), 2^-33 is the tie
  // (to even: 0) and everything below rounds to 0.
  EXPECT_EQ(exp2(Fixed::from_int(-32)), Fixed::epsilon());
  EXPECT_EQ(exp2(raw(-33 * kOne + 1)), Fixed::epsilon());
  EXPECT_EQ(exp2(raw(-33 * kOne)), Fixed::zero());
  EXPECT_EQ(exp2(raw(-33 * kOne - 1)), Fixed::zero());
  EXPECT_EQ(exp2(Fixed::min()), Fixed::zero());
}

TEST(FixedExpLog, ExpSaturationThreshold) {
  // e^x rounds to 2^31 (and saturates) exactly when x >= ln(2^31 - 2^-33) = 31 ln2 - 2^-64 (to
  // 1e-38). With T = floor(31 ln2 2^32) and a fraction well clear of 0 and 1, raw T is below the
  // threshold and raw T + 1 above it.
  const Scaled s = k_ln2_raw(31);
  ASSERT_TRUE(fraction_is_clear(s.fraction));
  const std::int64_t t = s.floor;
  // e^(T/2^32) = 2^31 e^(-f 2^-32) with f < 1: raw value in (2^63 - 2^31, 2^63).
  const Fixed at = exp(raw(t));
  EXPECT_NE(at, Fixed::max());
  EXPECT_GE(at.raw(), kMax - (std::int64_t{1} << 31) - (kMax >> 46)) << show(at);
  for (std::int64_t d = 1; d <= 1000; ++d)
    EXPECT_EQ(exp(raw(t + d)), Fixed::max()) << d;
  EXPECT_EQ(exp(Fixed::max()), Fixed::max());
  // Just below, the results are not saturated and increase.
  for (std::int64_t d = 1; d <= 1000; ++d)
    EXPECT_LE(exp(raw(t - d)), at) << d;
}

TEST(FixedExpLog, ExpUnderflowThreshold) {
  // e^x > 2^-33 (half an ulp) iff x > -33 ln2. With U = floor(33 ln2 2^32): raw -U is above the
  // threshold by (1 - f) 2^-32, so e^x = 2^-33 (1 + (1 - f) 2^-32 + ...), clearly above the tie:
  // rounds to one ulp. Raw -U - 1 is below it and rounds to 0.
  const Scaled s = k_ln2_raw(33);
  ASSERT_TRUE(fraction_is_clear(s.fraction));
  const std::int64_t u = s.floor;
  EXPECT_EQ(exp(raw(-u)), Fixed::epsilon());
  EXPECT_EQ(exp(raw(-u - 1)), Fixed::zero());
  for (std::int64_t d = 1; d <= 1000; ++d)
    EXPECT_EQ(exp(raw(-u - d)), Fixed::zero()) << d;
  EXPECT_EQ(exp(Fixed::from_int(-24)), Fixed::zero());
  EXPECT_EQ(exp(Fixed::min()), Fixed::zero());
  // One ulp is e^(-32 ln2): raw -floor(32 ln2 2^32) is above it, so the result is at least 1 ulp
  // (e^x in (2^-32, 1.5 2^-32): exactly one ulp).
  const Scaled s32 = k_ln2_raw(32);
  ASSERT_TRUE(fraction_is_clear(s32.fraction));
  EXPECT_EQ(exp(raw(-s32.floor)), Fixed::epsilon());
}

// ---- Properties ---------------------------------------------------------------------------------

/// Windows of consecutive raw inputs around each start, plus a strided sweep of [lo, hi].
std::vector<std::vector<std::int64_t>> sweeps(std::vector<std::int64_t> starts, std::int64_t lo,
                                              std::int64_t hi) {
  std::vector<std::vector<std::int64_t>> out;
  for (const std::int64_t s : starts) {
    std::vector<std::int64_t> w;
    for (std::int64_t d = -20000; d <= 20000; ++d)
      w.push_back(s + d);
    out.push_back(w);
  }
  std::vector<std::int64_t> strided;
  const std::int64_t step = (hi - lo) / 200000 | 1;
  for (std::int64_t r = lo; r <= hi - step; r += step)
    strided.push_back(r);
  out.push_back(strided);
  return out;
}

template <class F>
void expect_nondecreasing(const char* name, F f, const std::vector<std::vector<std::int64_t>>& s) {
  for (const auto& w : s) {
    Fixed prev = f(raw(w.front()));
    for (std::size_t i = 1; i < w.size(); ++i) {
      const Fixed cur = f(raw(w[i]));
      ASSERT_LE(prev, cur) << name << " decreases between raw " << w[i - 1] << " and " << w[i]
                           << ": " << show(prev) << " then " << show(cur);
      prev = cur;
    }
  }
}

TEST(FixedExpLog, Monotonic) {
  const Scaled s31 = k_ln2_raw(31);
  const Scaled s33 = k_ln2_raw(33);
  std::vector<std::int64_t> exp_starts = {0, kOne, -kOne, s31.floor, -s33.floor, 10 * kOne};
  for (const auto r : random_raws(6, -23 * kOne, 21 * kOne, 1))
    exp_starts.push_back(r);
  expect_nondecreasing(
      "exp", [](Fixed x) { return exp(x); }, sweeps(exp_starts, -24 * kOne, 22 * kOne));
  std::vector<std::int64_t> exp2_starts = {0, kOne, -kOne, 31 * kOne, -33 * kOne, -32 * kOne};
  for (const auto r : random_raws(6, -33 * kOne, 31 * kOne, 2))
    exp2_starts.push_back(r);
  expect_nondecreasing(
      "exp2", [](Fixed x) { return exp2(x); }, sweeps(exp2_starts, -34 * kOne, 32 * kOne));
  std::vector<std::int64_t> log_starts = {
      kOne, 2 * kOne, kOne / 2, kMax - 20000, 20001, std::int64_t{1} << 40, std::int64_t{1} << 60};
  for (const auto r : random_raws(6, 1, kMax, 3))
    log_starts.push_back(r);
  const auto log_sweeps = sweeps(log_starts, 1, kMax);
  expect_nondecreasing(
      "log", [](Fixed x) { return log(x); }, log_sweeps);
  expect_nondecreasing(
      "log2", [](Fixed x) { return log2(x); }, log_sweeps);
  for (const Fixed y : {0.5_fx, 2_fx, 3.7_fx, 31_fx, 1e-6_fx}) {
    expect_nondecreasing(
        "pow(., y)", [y](Fixed x) { return pow(x, y); },
        sweeps({kOne, kOne / 3, 5 * kOne}, 1, 64 * kOne));
  }
  for (const Fixed x : {1.5_fx, 1.0000001_fx, 7_fx}) {
    expect_nondecreasing(
        "pow(x, .)", [x](Fixed y) { return pow(x, y); },
        sweeps({0, kOne, -kOne, 2 * kOne}, -40 * kOne, 40 * kOne));
  }
}

TEST(FixedExpLog, RoundTrips) {
  // log(x) = L + d with |d| < 2^-32 (faithful), so exp(log(x)) = x e^d plus exp's own error:
  // |exp(log x) - x| <= x (e^(2^-32) - 1) + contract <= raw/2^32 + 1 + contract (raw units).
  // exp2(log2(x)) likewise, with 2^d - 1 < ln2 2^-32 < e^(2^-32) - 1.
  std::vector<std::int64_t> inputs = random_raws(200000, 1, kMax, 4);
  std::mt19937_64 rng(5);
  for (int i = 0; i < 200000; ++i)
    inputs.push_back(static_cast<std::int64_t>((rng() >> 1) >> (rng() % 63)) | 1);
  for (const std::int64_t r : inputs) {
    const Fixed x = raw(r);
    const std::uint64_t bound = (static_cast<std::uint64_t>(r) >> 32) + 1 + contract_ulps(r);
    const Fixed e = exp(log(x));
    ASSERT_LE(distance(e, x), bound) << show(x) << " -> " << show(log(x)) << " -> " << show(e);
    const Fixed b = exp2(log2(x));
    ASSERT_LE(distance(b, x), bound) << show(x) << " -> " << show(log2(x)) << " -> " << show(b);
  }
}

TEST(FixedExpLog, Exp2AgreesWithPowOfTwo) {
  // Both are 2^y: each within the contract of the exact value.
  for (const std::int64_t r : random_raws(100000, -34 * kOne, 32 * kOne, 6)) {
    const Fixed a = exp2(raw(r));
    const Fixed b = pow(Fixed::from_int(2), raw(r));
    EXPECT_LE(distance(a, b), 2 * contract_ulps(a.raw())) << show(raw(r));
  }
}

// ---- pow ----------------------------------------------------------------------------------------

TEST(FixedPow, DomainAndIdentities) {
  const std::vector<std::int64_t> xs = {1,        -1,   kOne, -kOne,    3 * kOne,    -3 * kOne,
                                        kOne / 3, kMax, kMin, kMin + 1, 12345678901, -12345678901};
  for (const std::int64_t xr : xs) {
    EXPECT_EQ(pow(raw(xr), Fixed::zero()), Fixed::one()) << xr;  // any x, also negative
    EXPECT_EQ(pow(raw(xr), Fixed::one()), raw(xr)) << xr;        // exact, even when huge
  }
  EXPECT_EQ(pow(Fixed::zero(), Fixed::zero()), Fixed::one());
  for (const std::int64_t yr :
       {std::int64_t{1}, kOne, 7 * kOne / 2, kMax, kMin, std::int64_t{-1}, -kOne}) {
    EXPECT_EQ(pow(Fixed::one(), raw(yr)), Fixed::one()) << yr;
    EXPECT_EQ(pow(Fixed::zero(), raw(yr)), yr > 0 ? Fixed::zero() : Fixed::max()) << yr;
  }
  // Negative x: a non-integer y gives 0, an integer y the sign of its parity.
  EXPECT_EQ(pow(-2_fx, 0.5_fx), Fixed::zero());
  EXPECT_EQ(pow(-2_fx, raw(kOne + 1)), Fixed::zero());
  EXPECT_EQ(pow(-2_fx, 3_fx), -8_fx);
  EXPECT_EQ(pow(-2_fx, 2_fx), 4_fx);
  EXPECT_EQ(pow(-2_fx, -1_fx), -0.5_fx);
  EXPECT_EQ(pow(-2_fx, -2_fx), 0.25_fx);
  EXPECT_EQ(pow(-2_fx, 31_fx), Fixed::min());  // exactly -2^31
  EXPECT_EQ(pow(-2_fx, 32_fx), Fixed::max());  // 2^32 saturates
  EXPECT_EQ(pow(-2_fx, 33_fx), Fixed::min());
  EXPECT_EQ(pow(Fixed::min(), 1_fx), Fixed::min());
  EXPECT_EQ(pow(Fixed::min(), 2_fx), Fixed::max());
  EXPECT_EQ(pow(Fixed::min(), -1_fx), raw(-2));  // -2^-31
  EXPECT_EQ(pow(-1_fx, raw(std::int64_t{2147483647} << 32)), -1_fx);
  EXPECT_EQ(pow(-1_fx, raw(std::int64_t{-2147483647} << 32)), -1_fx);
  EXPECT_EQ(pow(-1_fx, Fixed::min()), 1_fx);  // y = -2^31 is even
}

TEST(FixedPow, SmallIntegerExponentsAreExact) {
  EXPECT_EQ(pow(2_fx, 10_fx), 1024_fx);
  EXPECT_EQ(pow(3_fx, 19_fx), 1162261467_fx);
  EXPECT_EQ(pow(-3_fx, 19_fx), -1162261467_fx);
  EXPECT_EQ(pow(10_fx, 9_fx), 1000000000_fx);
  EXPECT_EQ(pow(1.5_fx, 4_fx), 5.0625_fx);
  EXPECT_EQ(pow(0.5_fx, 32_fx), Fixed::epsilon());
  EXPECT_EQ(pow(2_fx, -32_fx), Fixed::epsilon());
  EXPECT_EQ(pow(2_fx, 30_fx), raw(std::int64_t{1} << 62));
  EXPECT_EQ(pow(4_fx, 0.5_fx), 2_fx);
  EXPECT_EQ(pow(0.25_fx, 1.5_fx), 0.125_fx);
  EXPECT_EQ(pow(9_fx, 0.5_fx), 3_fx);
  // Wherever repeated multiplication is exact at every step (each product's low 32 bits are zero
  // and it stays in range), pow must give that exact value.
  std::mt19937_64 rng(7);
  int checked = 0;
  for (int i = 0; i < 200000; ++i) {
    // x = odd 2^(shift - 32): x^n is representable when shift n - 32 (n - 1) >= 0 and the odd part
    // is short enough. Shifts at the bound give results with odd raw values (up to 63 bits), the
    // hardest case for a logarithm route.
    const int n = 2 + static_cast<int>(rng() % 30);
    const int shift = (32 * (n - 1) + n - 1) / n + static_cast<int>(rng() % 3);
    const int spare = 63 - (shift * n - 32 * (n - 1));
    const int odd_bits = 1 + static_cast<int>(rng() % static_cast<std::uint64_t>(spare / n + 1));
    if (shift > 40 || odd_bits > 63 - shift) continue;
    const auto odd = static_cast<std::int64_t>((rng() >> (64 - odd_bits)) | 1U);
    const std::int64_t xr = (rng() & 1U) != 0 ? odd << shift : -(odd << shift);
    std::int64_t acc = xr;
    bool exact = true;
    for (int k = 1; k < n && exact; ++k) {
      const U128 p = wide::Portable::mul(detail::magnitude(acc), detail::magnitude(xr));
      const bool negative = (acc < 0) != (xr < 0);
      // exact iff the low 32 bits vanish and |p| / 2^32 fits (2^63 only for a negative result)
      const U128 q = wide::shr(p, 32);
      exact = (p.lo & 0xFFFFFFFFU) == 0 && q.hi == 0 &&
              (q.lo < (std::uint64_t{1} << 63) || (negative && q.lo == (std::uint64_t{1} << 63)));
      if (exact)
        acc = negative ? static_cast<std::int64_t>(0U - q.lo) : static_cast<std::int64_t>(q.lo);
    }
    if (!exact) continue;
    ++checked;
    ASSERT_EQ(pow(raw(xr), Fixed::from_int(n)), raw(acc)) << show(raw(xr)) << " ^ " << n;
  }
  EXPECT_GT(checked, 10000);
}

TEST(FixedPow, AgreesWithMultiplicationDivisionAndSqrt) {
  // x * x and 1 / x are correctly rounded, sqrt too; pow is within the contract of the same exact
  // value, so the two differ by at most 0.5 ulp + the contract, i.e. 1 ulp below 2^16.
  std::vector<std::int64_t> xs = random_raws(100000, 1, 46340 * kOne, 8);
  std::mt19937_64 rng(9);
  for (int i = 0; i < 100000; ++i)
    xs.push_back(static_cast<std::int64_t>((rng() >> 1) >> (rng() % 63)) | 1);
  for (const std::int64_t r : xs) {
    const Fixed x = raw(r);
    if (x < 46340_fx) {  // x^2 < 2^31
      const Fixed sq = x * x;
      EXPECT_LE(distance(pow(x, 2_fx), sq), contract_ulps(sq.raw())) << show(x);
      EXPECT_LE(distance(pow(-x, 2_fx), sq), contract_ulps(sq.raw())) << show(x);
    }
    const Fixed root = sqrt(x);
    EXPECT_LE(distance(pow(x, 0.5_fx), root), 1U) << show(x);
    const Fixed inv = Fixed::one() / x;
    if (inv != Fixed::max()) {
      EXPECT_LE(distance(pow(x, -1_fx), inv), contract_ulps(inv.raw())) << show(x);
    }
  }
}

TEST(FixedPow, NearOneWithHugeExponents) {
  // With e = 2^-32, ln(1 +- e) = +-e - e^2/2 +- e^3/3, so (each value is the series summed to 30
  // digits, i.e. e^(exponent) evaluated far beyond 2^-32):
  //   (1 + e)^(2^31 - e) = e^(1/2 - 2^-34 - (5/3) 2^-65 + ...) = 1.648721270604159938111228532
  //   (1 - e)^(-2^31)    = e^(1/2 + 2^-34 + (1/3) 2^-65 + ...) = 1.648721270796096355532074222
  //   (1 - e)^(2^31 - 1) = e^(-1/2 + 2^-33 - 2^-34 + ...)     = 0.606530659818547616546531052
  //   (1 + e)^(-2^31)    = e^(-1/2 + 2^-34 - (1/3) 2^-65 + ...) = 0.606530659747938154573521676
  // y log2(x) is needed to ~2^-60 absolute with y near 2^31: a 64-bit log2 would miss these.
  struct Case {
    Fixed x, y, exact;
  };
  const Case cases[] = {
      {raw(kOne + 1), Fixed::max(), 1.648721270604159938111228532_fx},
      {raw(kOne - 1), Fixed::min(), 1.648721270796096355532074222_fx},
      {raw(kOne - 1), 2147483647_fx, 0.606530659818547616546531052_fx},
      {raw(kOne + 1), Fixed::min(), 0.606530659747938154573521676_fx},
  };
  for (const Case& c : cases) {
    const Fixed got = pow(c.x, c.y);
    EXPECT_LE(distance(got, c.exact), 1U)
        << show(c.x) << " ^ " << show(c.y) << " = " << show(got) << ", exact " << show(c.exact);
  }
  // Overflow and underflow through a huge exponent: (1 +- 2^-20)^(+-2^31) = e^(+-2048).
  EXPECT_EQ(pow(raw(kOne + 4096), Fixed::max()), Fixed::max());
  EXPECT_EQ(pow(raw(kOne - 4096), Fixed::max()), Fixed::zero());
  EXPECT_EQ(pow(raw(kOne + 4096), Fixed::min()), Fixed::zero());
}

TEST(FixedPow, Underflow) {
  EXPECT_EQ(pow(0.5_fx, 33_fx), Fixed::zero());  // 2^-33: the tie rounds to even
  EXPECT_EQ(pow(0.5_fx, 34_fx), Fixed::zero());
  EXPECT_EQ(pow(2_fx, -33_fx), Fixed::zero());
  EXPECT_EQ(pow(Fixed::epsilon(), 2_fx), Fixed::zero());
  EXPECT_EQ(pow(Fixed::epsilon(), 1.5_fx), Fixed::zero());
  EXPECT_EQ(pow(Fixed::epsilon(), 0.5_fx), raw(65536));  // 2^-16 exactly
  EXPECT_EQ(pow(Fixed::max(), -2_fx), Fixed::zero());    // 2^-62
  EXPECT_EQ(pow(Fixed::max(), -1_fx), raw(2));           // 2^-31 (1 + 2^-63): rounds to 2 ulps
}

}  // namespace
}  // namespace detsim

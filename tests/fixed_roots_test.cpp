// sqrt, rsqrt, hypot and the integer root behind them (fixed/src/isqrt.hpp, also used for vector
// lengths), and normalisation (fixed/src/normalize.hpp). Every expected value is derived: either a
// closed form (sqrt(4) = 2, rsqrt(4^j ulp) = 2^(48-j) ulp, Pythagorean triples) or an exact
// 128/192-bit check of the rounding inequality that defines the correct result, computed with
// schoolbook multiplication (wide::Portable), never with the code under test.
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec2.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/fixed/wide.hpp>

#include "../fixed/src/isqrt.hpp"
#include "support/print.hpp"

namespace detsim {
namespace {

using wide::U128;

constexpr std::int64_t kOne = Fixed::one_raw;
constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMin = std::numeric_limits<std::int64_t>::min();
constexpr std::uint64_t kU64Max = std::numeric_limits<std::uint64_t>::max();
constexpr int kRandomSamples = 5'000'000;  // per distribution; two distributions per function

Fixed raw(std::int64_t r) {
  return Fixed::from_raw(r);
}

std::string show(Fixed x) {
  return ::testing::PrintToString(x);
}

std::string show(U128 v) {
  std::ostringstream os;
  os << "0x" << std::hex << v.hi << "_" << v.lo;
  return os.str();
}

// ---- Exact reference arithmetic, independent of roots.cpp --------------------------------------

U128 square(std::uint64_t s) {
  return wide::Portable::mul(s, s);
}

U128 u128(std::uint64_t v) {
  return U128{0, v};
}

/// s == round(sqrt(n)) exactly: (s - 1/2)^2 <= n < (s + 1/2)^2, which for integers reads
/// s^2 - s < n <= s^2 + s (the lower bound is vacuous for s = 0). No ties exist. s^2 + s fits in
/// 128 bits for every 64-bit s.
bool is_rounded_root(U128 n, std::uint64_t s) {
  const U128 s2 = square(s);
  const bool below_upper = !wide::less(wide::add(s2, u128(s)), n);  // n <= s^2 + s
  const bool above_lower = s == 0 || wide::less(wide::sub(s2, u128(s)), n);
  return below_upper && above_lower;
}

/// The true root is at least s - 1/2 (so a result saturated at s is right): n > s^2 - s.
bool root_at_least(U128 n, std::uint64_t s) {
  return wide::less(wide::sub(square(s), u128(s)), n);
}

/// round(sqrt(n)) by bisection on the inequality, for a handful of known values.
std::uint64_t reference_isqrt_round(U128 n) {
  std::uint64_t s = 0;  // the largest s with s^2 <= n
  for (int bit = 63; bit >= 0; --bit) {
    const std::uint64_t t = s | (std::uint64_t{1} << bit);
    if (!wide::less(n, square(t))) s = t;
  }
  const U128 rest = wide::sub(n, square(s));
  const bool up = wide::less(u128(s), rest);
  return up && s != kU64Max ? s + 1 : s;
}

/// 192-bit unsigned value, for u^2 r in the rsqrt check.
struct U192 {
  std::uint64_t top = 0;
  U128 low;
};

U192 square_times(std::uint64_t u, std::uint64_t r) {
  const U128 u2 = square(u);
  const U128 lo = wide::Portable::mul(u2.lo, r);
  const U128 hi = wide::Portable::mul(u2.hi, r);  // weight 2^64
  const U128 mid = wide::add(U128{0, lo.hi}, U128{0, hi.lo});
  return U192{hi.hi + mid.hi, U128{mid.lo, lo.lo}};
}

bool less(U192 a, U192 b) {
  return a.top < b.top || (a.top == b.top && wide::less(a.low, b.low));
}

/// y == round(2^48 / sqrt(r)), the raw result of rsqrt for raw input r > 0:
/// y - 1/2 <= 2^48 / sqrt(r) < y + 1/2  <=>  (2y - 1)^2 r <= 2^98 < (2y + 1)^2 r.
bool is_rounded_rsqrt(std::uint64_t r, std::uint64_t y) {
  if (y == 0 || y > (std::uint64_t{1} << 48)) return false;  // 2^48 / sqrt(r) <= 2^48 for r >= 1
  const U192 two_pow_98{0, U128{std::uint64_t{1} << 34, 0}};
  return !less(two_pow_98, square_times(2 * y - 1, r)) &&
         less(two_pow_98, square_times(2 * y + 1, r));
}

U128 sqrt_argument(std::int64_t r) {  // raw 2^32: sqrt(x) raw = round(sqrt(raw 2^32))
  const auto u = static_cast<std::uint64_t>(r);
  return U128{u >> 32, u << 32};
}

U128 sum_of_squares(std::int64_t x, std::int64_t y) {
  const std::uint64_t ax =
      x < 0 ? 0 - static_cast<std::uint64_t>(x) : static_cast<std::uint64_t>(x);
  const std::uint64_t ay =
      y < 0 ? 0 - static_cast<std::uint64_t>(y) : static_cast<std::uint64_t>(y);
  return wide::add(square(ax), square(ay));
}

// ---- Checks with bounded failure output --------------------------------------------------------

/// Runs exact checks over many inputs and reports the first ten failures in full (decimal and raw
/// hex), then the failure count.
class Checker {
 public:
  explicit Checker(std::string what) : what_(std::move(what)) {}
  ~Checker() {
    EXPECT_EQ(failures_, 0U) << what_ << ": " << failures_ << " of " << count_ << " inputs failed";
  }
  Checker(const Checker&) = delete;
  Checker& operator=(const Checker&) = delete;

  void sqrt(std::int64_t r) {
    ++count_;
    const Fixed s = detsim::sqrt(raw(r));
    const bool ok = r <= 0 ? s == Fixed{}
                           : s.raw() >= 0 && is_rounded_root(sqrt_argument(r),
                                                             static_cast<std::uint64_t>(s.raw()));
    if (!ok) report("sqrt(" + show(raw(r)) + ") = " + show(s));
  }

  void rsqrt(std::int64_t r) {
    ++count_;
    const Fixed y = detsim::rsqrt(raw(r));
    const bool ok = r <= 0 ? y == Fixed::max()
                           : y.raw() > 0 && is_rounded_rsqrt(static_cast<std::uint64_t>(r),
                                                             static_cast<std::uint64_t>(y.raw()));
    if (!ok) report("rsqrt(" + show(raw(r)) + ") = " + show(y));
  }

  void hypot(std::int64_t x, std::int64_t y) {
    ++count_;
    const Fixed h = detsim::hypot(raw(x), raw(y));
    const U128 n = sum_of_squares(x, y);
    const auto s = static_cast<std::uint64_t>(h.raw());
    // A result of max() is right when the true root is at least max() - 1/2 ulp.
    const bool ok = h.raw() >= 0 && (h.raw() == kMax ? root_at_least(n, s) : is_rounded_root(n, s));
    if (!ok) report("hypot(" + show(raw(x)) + ", " + show(raw(y)) + ") = " + show(h));
  }

  void isqrt(U128 n) {
    ++count_;
    const std::uint64_t s = detail::isqrt_round(n);
    // round(sqrt(n)) is 2^64 exactly when n > (2^64 - 1)^2 + (2^64 - 1) = 2^128 - 2^64.
    const bool saturates = wide::less(U128{kU64Max, 0}, n);
    const bool ok = saturates ? s == kU64Max : is_rounded_root(n, s);
    if (!ok) report("isqrt_round(" + show(n) + ") = " + show(u128(s)));
  }

  std::size_t count() const { return count_; }

 private:
  void report(const std::string& message) {
    if (++failures_ <= 10) ADD_FAILURE() << what_ << ": " << message;
  }

  std::string what_;
  std::size_t count_ = 0;
  std::size_t failures_ = 0;
};

// ---- Inputs ------------------------------------------------------------------------------------

/// Seeded so that every run checks the same inputs. mt19937_64's output sequence is fixed by the
/// standard (distributions are not, so none is used).
std::mt19937_64 seeded(std::uint64_t salt) {
  return std::mt19937_64{0x5EED0F5C0DE5ULL ^ salt};
}

/// A positive raw value whose bit length is uniform in [1, 63]: log-uniform magnitudes.
std::int64_t log_uniform_positive(std::mt19937_64& rng) {
  const auto bits = static_cast<unsigned>(rng() % 63) + 1;  // 1..63
  const std::uint64_t top = std::uint64_t{1} << (bits - 1);
  return static_cast<std::int64_t>(top | (rng() & (top - 1)));
}

std::int64_t random_sign(std::mt19937_64& rng, std::int64_t v) {
  return (rng() & 1U) != 0 ? -v : v;
}

/// Boundary inputs shared by the root tests.
std::vector<std::int64_t> edge_raws() {
  std::vector<std::int64_t> v = {0,        1,        2,        3,    4,        5,
                                 kMax,     kMax - 1, kMax - 2, kOne, kOne - 1, kOne + 1,
                                 kOne / 4, kOne * 4, -1,       -2,   kMin,     kMin + 1};
  for (int b = 0; b < 63; ++b) {  // powers of two and their neighbours
    const std::int64_t p = std::int64_t{1} << b;
    v.insert(v.end(), {p, p - 1, p + 1, -p});
  }
  return v;
}

// ---- sqrt --------------------------------------------------------------------------------------

TEST(FixedSqrt, KnownValues) {
  EXPECT_EQ(sqrt(Fixed::from_int(4)), Fixed::from_int(2));
  EXPECT_EQ(sqrt(Fixed::one()), Fixed::one());
  EXPECT_EQ(sqrt(Fixed::from_int(0)), Fixed::zero());
  EXPECT_EQ(sqrt(raw(kOne / 4)), Fixed::half());  // sqrt(1/4) = 1/2
  EXPECT_EQ(sqrt(Fixed::from_int(1 << 30)), Fixed::from_int(1 << 15));
  EXPECT_EQ(sqrt(raw(1)), raw(1 << 16));  // sqrt(2^-32) = 2^-16
  EXPECT_EQ(sqrt(raw(4)), raw(1 << 17));  // sqrt(2^-30) = 2^-15
  EXPECT_EQ(sqrt(Fixed::from_int(49)), Fixed::from_int(7));

  // sqrt(2): the one s with s^2 - s < 2 * 2^64 <= s^2 + s, found by bisection. It must also be the
  // library's constant.
  const std::uint64_t sqrt2 = reference_isqrt_round(U128{2, 0});
  ASSERT_TRUE(is_rounded_root(U128{2, 0}, sqrt2));
  EXPECT_EQ(sqrt(Fixed::from_int(2)).raw(), static_cast<std::int64_t>(sqrt2));
  EXPECT_EQ(Fixed::sqrt2().raw(), static_cast<std::int64_t>(sqrt2));

  // sqrt(max) = round(sqrt((2^63 - 1) 2^32)), by bisection.
  const std::uint64_t top = reference_isqrt_round(sqrt_argument(kMax));
  EXPECT_EQ(sqrt(Fixed::max()).raw(), static_cast<std::int64_t>(top));
}

TEST(FixedSqrt, NegativeAndZeroGiveZero) {
  for (const std::int64_t r :
       {std::int64_t{0}, std::int64_t{-1}, std::int64_t{-2}, -kOne, kMin, kMin + 1, -kMax}) {
    EXPECT_EQ(sqrt(raw(r)), Fixed::zero()) << show(raw(r));
  }
}

TEST(FixedSqrt, EdgesAreCorrectlyRounded) {
  Checker check("sqrt edges");
  for (const std::int64_t r : edge_raws())
    check.sqrt(r);
  // Integer squares k^2 (exact roots k) and their neighbours within 2 ulp.
  for (std::int64_t k = 0; k <= 46340; ++k) {
    const std::int64_t square_raw = k * k * kOne;
    for (std::int64_t d = -2; d <= 2; ++d)
      check.sqrt(square_raw + d);
    EXPECT_EQ(sqrt(raw(square_raw)).raw(), k * kOne);
  }
  // Raw perfect squares j^2: sqrt(j^2 2^-32) = j 2^-16 exactly.
  std::mt19937_64 rng = seeded(1);
  for (int i = 0; i < 100000; ++i) {
    const std::int64_t j = static_cast<std::int64_t>(rng() >> 33);  // < 2^31, j^2 < 2^62
    for (std::int64_t d = -2; d <= 2; ++d)
      check.sqrt(j * j + d);
    EXPECT_EQ(sqrt(raw(j * j)).raw(), j << 16);
  }
}

// Inputs next to the rounding boundaries: raw 2^32 = s^2 + s is the largest n that rounds down to s
// (the root is s + 1/2 - 1/(8s) + ...), and one raw step more rounds up.
TEST(FixedSqrt, HalfwayNeighboursRoundCorrectly) {
  Checker check("sqrt near s + 1/2");
  // s = j 2^32 or j 2^32 - 1 makes s^2 + s a multiple of 2^32: raw r = (s^2 + s) / 2^32 has the
  // root s + 1/2 - 1/(8s) + ..., within 2^-35 ulp of a tie, and must round down; r + 1 adds
  // 2^32 <= 2s + 2 to n and must round up.
  for (std::uint64_t j = 1; j <= 46340; ++j) {
    for (const std::uint64_t s : {j << 32, (j << 32) - 1}) {
      const U128 boundary = wide::add(square(s), u128(s));  // s^2 + s, exact multiple of 2^32
      ASSERT_EQ(boundary.lo & 0xFFFFFFFFU, 0U);
      const auto r = static_cast<std::int64_t>((boundary.hi << 32) | (boundary.lo >> 32));
      EXPECT_EQ(sqrt(raw(r)).raw(), static_cast<std::int64_t>(s)) << show(raw(r));
      EXPECT_EQ(sqrt(raw(r + 1)).raw(), static_cast<std::int64_t>(s + 1)) << show(raw(r + 1));
      check.sqrt(r - 1);
    }
  }
  // Random s: the raw values around (s^2 + s) / 2^32.
  std::mt19937_64 rng = seeded(2);
  for (int i = 0; i < 1'000'000; ++i) {
    const std::uint64_t s = rng() >> (17 + rng() % 40);  // up to 2^47
    const U128 boundary = wide::add(square(s), u128(s));
    const auto r = static_cast<std::int64_t>((boundary.hi << 32) | (boundary.lo >> 32));
    for (std::int64_t d = -1; d <= 2; ++d)
      check.sqrt(r + d);
  }
}

TEST(FixedSqrt, UniformRawIsCorrectlyRounded) {
  Checker check("sqrt uniform");
  std::mt19937_64 rng = seeded(3);
  for (int i = 0; i < kRandomSamples; ++i)
    check.sqrt(static_cast<std::int64_t>(rng() >> 1));
}

TEST(FixedSqrt, LogUniformIsCorrectlyRounded) {
  Checker check("sqrt log-uniform");
  std::mt19937_64 rng = seeded(4);
  for (int i = 0; i < kRandomSamples; ++i)
    check.sqrt(log_uniform_positive(rng));
}

TEST(FixedSqrt, OfAnExactSquareIsTheMagnitude) {
  // x = a 2^-16 has x * x = a^2 2^-32 exactly (raw a^2), so sqrt(x * x) must be |x| exactly.
  std::mt19937_64 rng = seeded(5);
  for (int i = 0; i < 100000; ++i) {
    const auto a = static_cast<std::int64_t>(rng() % 3037000499ULL);  // a^2 <= 2^63 - 1
    const Fixed x = raw(random_sign(rng, a << 16));
    const Fixed xx = x * x;
    ASSERT_EQ(xx.raw(), a * a) << show(x);
    ASSERT_EQ(sqrt(xx), abs(x)) << show(x);
  }
}

// ---- rsqrt -------------------------------------------------------------------------------------

TEST(FixedRsqrt, KnownValues) {
  EXPECT_EQ(rsqrt(Fixed::one()), Fixed::one());
  EXPECT_EQ(rsqrt(Fixed::from_int(4)), Fixed::half());
  EXPECT_EQ(rsqrt(raw(kOne / 4)), Fixed::from_int(2));
  EXPECT_EQ(rsqrt(Fixed::from_int(1 << 30)), raw(kOne >> 15));
  // raw 4^j is the value 2^(2j - 32): its rsqrt is 2^(16 - j), raw 2^(48 - j), exactly.
  for (int j = 0; j <= 31; ++j) {
    EXPECT_EQ(rsqrt(raw(std::int64_t{1} << (2 * j))).raw(), std::int64_t{1} << (48 - j)) << j;
  }
  EXPECT_EQ(rsqrt(Fixed::epsilon()), Fixed::from_int(1 << 16));  // the largest result
}

TEST(FixedRsqrt, NonPositiveGivesMax) {
  for (const std::int64_t r : {std::int64_t{0}, std::int64_t{-1}, -kOne, kMin, -kMax}) {
    EXPECT_EQ(rsqrt(raw(r)), Fixed::max()) << show(raw(r));
  }
}

TEST(FixedRsqrt, EdgesAreCorrectlyRounded) {
  Checker check("rsqrt edges");
  for (const std::int64_t r : edge_raws())
    check.rsqrt(r);
  for (std::int64_t k = 1; k <= 46340; ++k) {  // integer squares and neighbours
    for (std::int64_t d = -2; d <= 2; ++d)
      check.rsqrt(k * k * kOne + d);
  }
  for (std::int64_t r = 1; r <= 100000; ++r)
    check.rsqrt(r);  // the steepest part, results ~2^16
}

// The result is y + 1/2 exactly when (2y + 1)^2 r = 2^98, which never happens; r = 2^98 / (2y +
// 1)^2 rounded down or up lands next to that tie. For large r the gap is below 2^-40 ulp.
TEST(FixedRsqrt, HalfwayNeighboursRoundCorrectly) {
  Checker check("rsqrt near y + 1/2");
  const U128 two_pow_98{std::uint64_t{1} << 34, 0};
  std::mt19937_64 rng = seeded(17);
  for (int i = 0; i < 1'000'000; ++i) {
    // y from 92682 (the smallest with r < 2^63) upwards: mostly results below 2^18, where the
    // gaps are smallest, and some of every size up to 2^48.
    const std::uint64_t y =
        i % 4 == 0 ? 92682 + (rng() >> (16 + rng() % 48)) : 92682 + rng() % 170000;
    const std::uint64_t u = 2 * y + 1;
    const U128 u2 = square(u);  // > 2^34, so the quotient fits in 64 bits
    const std::uint64_t below = u2.hi == 0 ? wide::Portable::div(two_pow_98, u2.lo).quotient : 0;
    if (below == 0 || below >= static_cast<std::uint64_t>(kMax)) continue;
    check.rsqrt(static_cast<std::int64_t>(below));
    check.rsqrt(static_cast<std::int64_t>(below) + 1);
  }
  EXPECT_GT(check.count(), 1'000'000U);
}

TEST(FixedRsqrt, UniformRawIsCorrectlyRounded) {
  Checker check("rsqrt uniform");
  std::mt19937_64 rng = seeded(6);
  for (int i = 0; i < kRandomSamples; ++i)
    check.rsqrt(static_cast<std::int64_t>(rng() >> 1));
}

TEST(FixedRsqrt, LogUniformIsCorrectlyRounded) {
  Checker check("rsqrt log-uniform");
  std::mt19937_64 rng = seeded(7);
  for (int i = 0; i < kRandomSamples; ++i)
    check.rsqrt(log_uniform_positive(rng));
}

// ---- hypot -------------------------------------------------------------------------------------

TEST(FixedHypot, PythagoreanTriplesAreExact) {
  struct Triple {
    std::int64_t a, b, c;
  };
  std::mt19937_64 rng = seeded(8);
  for (const Triple t : {Triple{3, 4, 5}, Triple{5, 12, 13}, Triple{8, 15, 17}, Triple{20, 21, 29},
                         Triple{119, 120, 169}}) {
    for (int i = 0; i < 10000; ++i) {
      // Any common scale keeps the triple exact; keep c * scale within the raw range.
      const auto scale =
          static_cast<std::int64_t>(rng() % (static_cast<std::uint64_t>(kMax) / 169));
      const Fixed a = raw(random_sign(rng, t.a * scale));
      const Fixed b = raw(random_sign(rng, t.b * scale));
      ASSERT_EQ(hypot(a, b), raw(t.c * scale)) << show(a) << ", " << show(b);
    }
  }
}

TEST(FixedHypot, WithZeroIsTheMagnitude) {
  std::mt19937_64 rng = seeded(9);
  std::vector<std::int64_t> inputs = edge_raws();
  for (int i = 0; i < 100000; ++i)
    inputs.push_back(random_sign(rng, log_uniform_positive(rng)));
  for (const std::int64_t r : inputs) {
    ASSERT_EQ(hypot(raw(r), Fixed::zero()), abs(raw(r))) << show(raw(r));
    ASSERT_EQ(hypot(Fixed::zero(), raw(r)), abs(raw(r))) << show(raw(r));
  }
}

TEST(FixedHypot, IsSymmetricAndSignIndependent) {
  std::mt19937_64 rng = seeded(10);
  for (int i = 0; i < 200000; ++i) {
    const std::int64_t x =
        i % 2 == 0 ? log_uniform_positive(rng) : static_cast<std::int64_t>(rng() >> 1);
    const std::int64_t y = log_uniform_positive(rng);
    const Fixed h = hypot(raw(x), raw(y));
    ASSERT_EQ(hypot(raw(y), raw(x)), h) << show(raw(x)) << ", " << show(raw(y));
    ASSERT_EQ(hypot(raw(-x), raw(y)), h) << show(raw(x)) << ", " << show(raw(y));
    ASSERT_EQ(hypot(raw(x), raw(-y)), h) << show(raw(x)) << ", " << show(raw(y));
    ASSERT_EQ(hypot(raw(-y), raw(-x)), h) << show(raw(x)) << ", " << show(raw(y));
  }
}

TEST(FixedHypot, SaturatesWithoutIntermediateOverflow) {
  EXPECT_EQ(hypot(Fixed::max(), Fixed::max()), Fixed::max());
  EXPECT_EQ(hypot(Fixed::min(), Fixed::min()), Fixed::max());
  EXPECT_EQ(hypot(Fixed::min(), Fixed::max()), Fixed::max());
  EXPECT_EQ(hypot(Fixed::max(), Fixed::epsilon()), Fixed::max());
  EXPECT_EQ(hypot(Fixed::min(), Fixed::zero()), Fixed::max());  // |min| = 2^31 saturates too
  // Components whose squares overflow Fixed (2^40 > 2^31) but whose hypot does not: 2^20 sqrt(2).
  const Fixed big = Fixed::from_int(1 << 20);
  const std::uint64_t expected = reference_isqrt_round(sum_of_squares(big.raw(), big.raw()));
  EXPECT_EQ(hypot(big, big).raw(), static_cast<std::int64_t>(expected));
  EXPECT_LT(hypot(big, big), Fixed::max());

  Checker check("hypot near saturation");
  std::mt19937_64 rng = seeded(11);
  for (int i = 0; i < 100000; ++i) {  // |x|, |y| near 2^63: results around the saturation edge
    const std::int64_t x = kMax - static_cast<std::int64_t>(rng() >> (1 + rng() % 63));
    const std::int64_t y = static_cast<std::int64_t>(rng() >> (1 + rng() % 63));
    check.hypot(random_sign(rng, x), random_sign(rng, y));
  }
}

TEST(FixedHypot, EdgesAreCorrectlyRounded) {
  Checker check("hypot edges");
  const std::vector<std::int64_t> edges = edge_raws();
  for (const std::int64_t x : edges) {
    for (const std::int64_t y : edges)
      check.hypot(x, y);
  }
}

TEST(FixedHypot, UniformRawIsCorrectlyRounded) {
  Checker check("hypot uniform");
  std::mt19937_64 rng = seeded(12);
  for (int i = 0; i < kRandomSamples; ++i) {
    check.hypot(static_cast<std::int64_t>(rng()), static_cast<std::int64_t>(rng()));
  }
}

TEST(FixedHypot, LogUniformIsCorrectlyRounded) {
  Checker check("hypot log-uniform");
  std::mt19937_64 rng = seeded(13);
  for (int i = 0; i < kRandomSamples; ++i) {
    const std::int64_t x = random_sign(rng, log_uniform_positive(rng));
    check.hypot(x, random_sign(rng, log_uniform_positive(rng)));
  }
}

// ---- hypot_exceeds and length_exceeds: the comparison without the root -------------------------

/// Limits around a root's raw value h, and the fixed ones where the comparison's cases change.
std::vector<std::int64_t> limits_around(std::int64_t h, std::mt19937_64& rng) {
  std::vector<std::int64_t> l = {0, -1, kMin, kMax, kMax - 1, static_cast<std::int64_t>(rng())};
  for (const std::int64_t d : {-2, -1, 0, 1, 2}) {
    if ((d < 0 && h >= kMin - d) || (d >= 0 && h <= kMax - d)) l.push_back(h + d);
  }
  return l;
}

TEST(FixedHypot, ExceedsAgreesWithTheRoundedRoot) {
  std::mt19937_64 rng = seeded(17);
  std::vector<std::pair<std::int64_t, std::int64_t>> inputs;
  const std::vector<std::int64_t> edges = edge_raws();
  for (const std::int64_t x : edges) {
    for (const std::int64_t y : {std::int64_t{0}, std::int64_t{1}, kOne, kMax, kMin})
      inputs.emplace_back(x, y);
  }
  for (int i = 0; i < 300000; ++i) {
    inputs.emplace_back(random_sign(rng, log_uniform_positive(rng)),
                        random_sign(rng, log_uniform_positive(rng)));
  }
  for (int i = 0; i < 100000; ++i)  // near saturation
    inputs.emplace_back(kMax - static_cast<std::int64_t>(rng() >> (1 + rng() % 63)),
                        static_cast<std::int64_t>(rng() >> (1 + rng() % 63)));
  for (const auto& [x, y] : inputs) {
    const Fixed h = hypot(raw(x), raw(y));
    for (const std::int64_t l : limits_around(h.raw(), rng)) {
      ASSERT_EQ(hypot_exceeds(raw(x), raw(y), raw(l)), h > raw(l))
          << show(raw(x)) << ", " << show(raw(y)) << " against " << show(raw(l));
    }
  }
}

TEST(FixedHypot, LengthExceedsAgreesWithTheRoundedLength) {
  std::mt19937_64 rng = seeded(18);
  std::vector<Vec3> inputs;
  for (const std::int64_t x : edge_raws()) {
    for (const std::int64_t y : {std::int64_t{0}, std::int64_t{-1}, kOne, kMax, kMin})
      inputs.push_back({raw(x), raw(y), raw(x == kMin ? 0 : -x)});
  }
  for (int i = 0; i < 300000; ++i) {
    inputs.push_back({raw(random_sign(rng, log_uniform_positive(rng))),
                      raw(random_sign(rng, log_uniform_positive(rng))),
                      raw(i % 2 == 0 ? static_cast<std::int64_t>(rng())
                                     : random_sign(rng, log_uniform_positive(rng)))});
  }
  for (const Vec3& v : inputs) {
    const Fixed h = length(v);
    for (const std::int64_t l : limits_around(h.raw(), rng)) {
      ASSERT_EQ(length_exceeds(v, raw(l)), h > raw(l))
          << show(v.x) << ", " << show(v.y) << ", " << show(v.z) << " against " << show(raw(l));
    }
  }
}

// ---- The integer core over its whole 128-bit domain --------------------------------------------

TEST(IsqrtRound, EdgesOfTheDomain) {
  Checker check("isqrt_round edges");
  const U128 all_ones{kU64Max, kU64Max};
  EXPECT_EQ(detail::isqrt_round(U128{0, 0}), 0U);
  EXPECT_EQ(detail::isqrt_round(U128{0, 1}), 1U);
  EXPECT_EQ(detail::isqrt_round(U128{0, 2}), 1U);  // sqrt 2 = 1.41
  EXPECT_EQ(detail::isqrt_round(U128{0, 3}), 2U);  // sqrt 3 = 1.73
  EXPECT_EQ(detail::isqrt_round(U128{1, 0}), std::uint64_t{1} << 32);
  // (2^64 - 1)^2 + (2^64 - 1) = 2^128 - 2^64 is the last n whose root rounds below 2^64.
  EXPECT_EQ(detail::isqrt_round(U128{kU64Max, 0}), kU64Max);
  EXPECT_EQ(detail::isqrt_round(U128{kU64Max, 1}), kU64Max);  // saturated
  EXPECT_EQ(detail::isqrt_round(all_ones), kU64Max);          // saturated
  for (unsigned b = 0; b < 128; ++b) {                        // powers of two and neighbours
    const U128 p = wide::shl(U128{0, 1}, b);
    check.isqrt(p);
    check.isqrt(wide::sub(p, U128{0, 1}));
    check.isqrt(wide::add(p, U128{0, 1}));
  }
  std::mt19937_64 rng = seeded(14);
  for (int i = 0; i < 200000; ++i) {  // s^2, s^2 + s and their neighbours, s of every size
    const std::uint64_t s = rng() >> (rng() % 64);
    const U128 s2 = square(s);
    const U128 s2s = wide::add(s2, u128(s));
    for (const U128 n : {s2, s2s}) {
      check.isqrt(n);
      check.isqrt(wide::add(n, U128{0, 1}));
      check.isqrt(wide::sub(n, U128{0, 1}));
    }
  }
}

// The normalised high word m.hi alone decides the first estimate of the root; at the 48 largest
// values of m.hi that estimate is closest to overflowing (roots.cpp). n >= 2^126 is its own
// normalisation, so these inputs reach every such m.hi.
TEST(IsqrtRound, TopOfTheRange) {
  Checker check("isqrt_round top of the range");
  std::mt19937_64 rng = seeded(18);
  for (std::uint64_t hi = kU64Max - 255; hi != 0; ++hi) {  // wraps to 0 after kU64Max
    for (const std::uint64_t lo : {std::uint64_t{0}, std::uint64_t{1}, kU64Max, rng(), rng()}) {
      check.isqrt(U128{hi, lo});
    }
  }
  EXPECT_EQ(check.count(), 256U * 5U);
}

TEST(IsqrtRound, RandomOverTheWholeDomain) {
  Checker check("isqrt_round random");
  std::mt19937_64 rng = seeded(15);
  for (int i = 0; i < kRandomSamples; ++i) {
    check.isqrt(U128{rng(), rng()});                                                 // uniform
    check.isqrt(wide::shr(U128{rng(), rng()}, static_cast<unsigned>(rng() % 128)));  // log-uniform
  }
}

TEST(IsqrtRound, ThreeComponentLengths) {
  // hypot_raw(x, y, z): the vector length, up to sqrt(3) 2^63 before saturation.
  EXPECT_EQ(detail::hypot_raw(kMin, kMin, kMin), kMax);
  EXPECT_EQ(detail::hypot_raw(kMax, 0, 0), kMax);
  EXPECT_EQ(detail::hypot_raw(0, 0, 0), 0);
  EXPECT_EQ(detail::hypot_raw(2 * kOne, -3 * kOne, 6 * kOne), 7 * kOne);  // 4 + 9 + 36 = 49
  EXPECT_EQ(detail::hypot_raw(-1, 2, -2), 3);                             // in ulps
  std::mt19937_64 rng = seeded(16);
  std::size_t failures = 0;
  for (int i = 0; i < 1'000'000; ++i) {
    const std::int64_t x = random_sign(rng, log_uniform_positive(rng));
    const std::int64_t y = random_sign(rng, log_uniform_positive(rng));
    const std::int64_t z =
        i % 2 == 0 ? static_cast<std::int64_t>(rng()) : log_uniform_positive(rng);
    const U128 n = wide::add(sum_of_squares(x, y), sum_of_squares(z, 0));
    const std::int64_t h = detail::hypot_raw(x, y, z);
    const auto s = static_cast<std::uint64_t>(h);
    const bool ok = h >= 0 && (h == kMax ? root_at_least(n, s) : is_rounded_root(n, s));
    if (!ok && ++failures <= 10) {
      ADD_FAILURE() << "hypot_raw(" << show(raw(x)) << ", " << show(raw(y)) << ", " << show(raw(z))
                    << ") = " << show(raw(h));
    }
  }
  EXPECT_EQ(failures, 0U);
}

// ---- Normalisation: each component divided by the rounded length, rounded once ----------------

/// The definition of normalize (fixed/src/normalize.hpp), computed independently: magnitudes
/// shifted so that the largest is in [2^62, 2^63] (four components of 2^63 halved first, ties to
/// even), L = round(sqrt(S)) of their sum of squares, and each component m_i 2^32 / L rounded to
/// nearest, ties to even, by one schoolbook division. Counts the quotients within 2^-9 of a
/// halfway point and the exact ties, so that tests can show they reach those cases.
struct NormalizeReference {
  std::size_t near_halfway = 0;
  std::size_t ties = 0;

  template <std::size_t N>
  std::array<std::int64_t, N> operator()(std::array<std::int64_t, N> c) {
    std::array<std::uint64_t, N> m{};
    std::uint64_t largest = 0;
    for (std::size_t i = 0; i < N; ++i) {
      m[i] = c[i] < 0 ? 0 - static_cast<std::uint64_t>(c[i]) : static_cast<std::uint64_t>(c[i]);
      largest = std::max(largest, m[i]);
    }
    if (N == 4 && largest == (std::uint64_t{1} << 63)) {
      for (std::uint64_t& mi : m)
        mi = (mi >> 1) + (mi & (mi >> 1) & 1U);
      largest >>= 1;
    }
    const int shift = std::max(std::countl_zero(largest) - 1, 0);
    U128 sum{};
    for (std::uint64_t& mi : m) {
      mi <<= shift;
      sum = wide::add(sum, square(mi));
    }
    const std::uint64_t length = reference_isqrt_round(sum);
    std::array<std::int64_t, N> result{};
    for (std::size_t i = 0; i < N; ++i) {
      const wide::DivResult qr = wide::Portable::div(U128{m[i] >> 32, m[i] << 32}, length);
      // Twice the remainder against the divisor, in 65 bits: 2r - L in (-L, L).
      const U128 twice_r = wide::shl(u128(qr.remainder), 1);
      const bool tie = twice_r == u128(length);
      const bool up = wide::less(u128(length), twice_r) || (tie && (qr.quotient & 1U) != 0);
      // Within 2^-9 of the halfway point: |2r - L| < L 2^-8.
      const U128 distance = wide::less(twice_r, u128(length)) ? wide::sub(u128(length), twice_r)
                                                              : wide::sub(twice_r, u128(length));
      near_halfway += wide::less(wide::shl(distance, 8), u128(length)) ? 1U : 0U;
      ties += tie ? 1U : 0U;
      const std::uint64_t q = qr.quotient + (up ? 1U : 0U);  // <= 2^32
      result[i] = c[i] < 0 ? -static_cast<std::int64_t>(q) : static_cast<std::int64_t>(q);
    }
    return result;
  }
};

/// normalize of the raw components through the public Vec2, Vec3 and Quat functions.
template <std::size_t N>
std::array<std::int64_t, N> normalize_raws(const std::array<std::int64_t, N>& c) {
  if constexpr (N == 2) {
    const Vec2 n = normalize(Vec2{raw(c[0]), raw(c[1])});
    return {n.x.raw(), n.y.raw()};
  } else if constexpr (N == 3) {
    const Vec3 n = normalize(Vec3{raw(c[0]), raw(c[1]), raw(c[2])});
    return {n.x.raw(), n.y.raw(), n.z.raw()};
  } else {
    const Quat n = normalize(Quat{raw(c[0]), raw(c[1]), raw(c[2]), raw(c[3])});
    return {n.w.raw(), n.x.raw(), n.y.raw(), n.z.raw()};
  }
}

template <std::size_t N>
std::string show(const std::array<std::int64_t, N>& c) {
  std::string s = "(";
  for (std::size_t i = 0; i < N; ++i)
    s += (i == 0 ? "" : ", ") + show(raw(c[i]));
  return s + ")";
}

/// Compares normalize with the reference over inputs from make(rng), which must not be zero.
template <std::size_t N, typename Make>
void check_normalize(NormalizeReference& reference, std::mt19937_64& rng, int count, Make make) {
  std::size_t failures = 0;
  for (int i = 0; i < count; ++i) {
    const std::array<std::int64_t, N> c = make(rng);
    const std::array<std::int64_t, N> expected = reference(c);
    const std::array<std::int64_t, N> actual = normalize_raws(c);
    if (actual != expected && ++failures <= 10) {
      ADD_FAILURE() << "normalize" << show(c) << " = " << show(actual) << ", expected "
                    << show(expected);
    }
  }
  EXPECT_EQ(failures, 0U) << "normalize of " << N << " components";
}

TEST(Normalize, IsTheRoundedQuotientByTheRoundedLength) {
  NormalizeReference reference;
  std::mt19937_64 rng = seeded(19);
  const auto component = [](std::mt19937_64& r) {
    switch (r() % 4) {
      case 0:
        return std::int64_t{0};
      case 1:
        return static_cast<std::int64_t>(r());  // any raw value, kMin included in principle
      default:
        return random_sign(r, log_uniform_positive(r));
    }
  };
  const auto nonzero = [&](auto c) {
    if (c[0] == 0) c[0] = 1;
    return c;
  };
  check_normalize<2>(reference, rng, 300'000, [&](std::mt19937_64& r) {
    return nonzero(std::array{component(r), component(r)});
  });
  check_normalize<3>(reference, rng, 300'000, [&](std::mt19937_64& r) {
    return nonzero(std::array{component(r), component(r), component(r)});
  });
  check_normalize<4>(reference, rng, 300'000, [&](std::mt19937_64& r) {
    return nonzero(std::array{component(r), component(r), component(r), component(r)});
  });
  // Unit-size quaternions and vectors near the unit sphere, as the simulation renormalises them.
  const auto near_unit = [](std::mt19937_64& r) {
    return random_sign(r, static_cast<std::int64_t>(r() >> 33));  // below 2^31: |.| < 1/2
  };
  check_normalize<4>(reference, rng, 300'000, [&](std::mt19937_64& r) {
    return nonzero(std::array{near_unit(r), near_unit(r), near_unit(r), near_unit(r)});
  });
  check_normalize<3>(reference, rng, 100'000, [&](std::mt19937_64& r) {
    return nonzero(std::array{near_unit(r), near_unit(r), near_unit(r)});
  });
  // Extremes: kMin, kMax and their neighbours in every position.
  const std::array<std::int64_t, 8> extremes{kMin, kMin + 1, kMax, kMax - 1, 1, -1, 0, kOne};
  check_normalize<4>(reference, rng, 100'000, [&](std::mt19937_64& r) {
    return nonzero(
        std::array{extremes[r() % 8], extremes[r() % 8], extremes[r() % 8], extremes[r() % 8]});
  });
  // normalize computes the length and divides only near a halfway point; the inputs above must
  // reach that path often.
  EXPECT_GT(reference.near_halfway, 10'000U);
}

// Exact ties m_i 2^33 = (2j + 1) L: with L = 2^33 u (u in [2^29, 2^30), L in [2^62, 2^63)) and m_0
// = u v for odd v, m_0 2^32 / L = v / 2 exactly, and m_1 ~ u sqrt(2^66 - v^2) puts the rounded
// length at L in most cases. Ties round to even.
TEST(Normalize, ExactTiesRoundToEven) {
  NormalizeReference reference;
  std::mt19937_64 rng = seeded(20);
  const auto tie_candidate = [](std::mt19937_64& r) {
    const std::uint64_t u = (std::uint64_t{1} << 29) | (r() >> 35);  // [2^29, 2^30)
    const std::uint64_t v = (r() >> 31) | 1U;                        // odd, < 2^33
    // m_1 = round(u sqrt(2^66 - v^2)) = round(sqrt(u^2 (2^66 - v^2))), with u^2 (2^66 - v^2) <
    // 2^126.
    const U128 two_66_minus = wide::sub(U128{4, 0}, square(v));
    const U128 product =
        wide::add(wide::Portable::mul(two_66_minus.lo, u * u), U128{two_66_minus.hi * u * u, 0});
    const std::uint64_t m1 = reference_isqrt_round(product);
    return std::array{random_sign(r, static_cast<std::int64_t>(u * v)),
                      random_sign(r, static_cast<std::int64_t>(m1))};
  };
  check_normalize<2>(reference, rng, 20'000, tie_candidate);
  check_normalize<3>(reference, rng, 20'000, [&](std::mt19937_64& r) {
    const auto c = tie_candidate(r);
    return std::array{c[1], std::int64_t{0}, c[0]};
  });
  check_normalize<4>(reference, rng, 20'000, [&](std::mt19937_64& r) {
    const auto c = tie_candidate(r);
    return std::array{std::int64_t{0}, c[0], std::int64_t{0}, c[1]};
  });
  EXPECT_GT(reference.ties, 10'000U);
}

}  // namespace
}  // namespace detsim

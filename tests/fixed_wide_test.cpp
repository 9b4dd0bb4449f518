// The two 128-bit paths: Portable (plain 64-bit C++, used where the compiler has no __int128) and
// Native (__int128). Both are compiled in every build; they must agree bit for bit, and Portable
// must also agree with a bit-serial reference that shares no code with either.
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/fixed/exact_sum.hpp>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/mat3.hpp>
#include <detsim/fixed/vec2.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/fixed/wide.hpp>

#include "support/scale.hpp"

namespace detsim {
namespace {

using wide::U128;

// Shift-and-add multiplication, one bit at a time.
U128 serial_mul(std::uint64_t a, std::uint64_t b) {
  U128 result{};
  U128 addend{0, a};
  for (int bit = 0; bit < 64; ++bit) {
    if (((b >> bit) & 1U) != 0) result = wide::add(result, addend);
    addend = wide::shl(addend, 1);
  }
  return result;
}

// Restoring long division, one quotient bit at a time (requires n.hi < d).
wide::DivResult serial_div(U128 n, std::uint64_t d) {
  U128 rem{};
  std::uint64_t q = 0;
  for (int bit = 127; bit >= 0; --bit) {
    rem = wide::shl(rem, 1);
    const std::uint64_t next = bit >= 64 ? (n.hi >> (bit - 64)) & 1U : (n.lo >> bit) & 1U;
    rem.lo |= next;
    if (!wide::less(rem, U128{0, d})) {
      rem = wide::sub(rem, U128{0, d});
      if (bit < 64) q |= std::uint64_t{1} << bit;
    }
  }
  return {q, rem.lo};
}

std::vector<std::uint64_t> operands(std::size_t n, std::uint64_t seed) {
  std::vector<std::uint64_t> v = {0,
                                  1,
                                  2,
                                  3,
                                  0xFFFFFFFFU,
                                  0x100000000U,
                                  0x80000000U,
                                  ~std::uint64_t{0},
                                  ~std::uint64_t{0} - 1,
                                  std::uint64_t{1} << 63,
                                  (std::uint64_t{1} << 63) - 1,
                                  (std::uint64_t{1} << 63) + 1,
                                  0xFFFFFFFF00000000U,
                                  0x00000001FFFFFFFFU};
  std::mt19937_64 rng(seed);
  while (v.size() < n) {
    const std::uint64_t bits = rng();
    const unsigned width = static_cast<unsigned>(rng() % 65);
    v.push_back(width == 64 ? bits : bits & ((std::uint64_t{1} << width) - 1));
  }
  return v;
}

constexpr std::size_t kCount = 10'000'000;

#if DETSIM_HAS_INT128
TEST(WidePaths, PortableMulEqualsNativeOnTenMillionOperands) {
  const auto v = operands(kCount + 1, 11);
  for (std::size_t i = 0; i < kCount; ++i) {
    ASSERT_EQ(wide::Portable::mul(v[i], v[i + 1]), wide::Native::mul(v[i], v[i + 1]))
        << v[i] << " * " << v[i + 1];
  }
}

TEST(WidePaths, PortableDivEqualsNativeOnTenMillionOperands) {
  const auto v = operands(kCount + 2, 12);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < kCount; ++i) {
    const std::uint64_t d = v[i + 2] == 0 ? 1 : v[i + 2];
    const U128 n{v[i] % d, v[i + 1]};  // hi < d: the quotient fits in 64 bits
    const auto p = wide::Portable::div(n, d);
    const auto q = wide::Native::div(n, d);
    ASSERT_EQ(p.quotient, q.quotient) << n.hi << ":" << n.lo << " / " << d;
    ASSERT_EQ(p.remainder, q.remainder) << n.hi << ":" << n.lo << " / " << d;
    ++checked;
  }
  EXPECT_EQ(checked, kCount);
}

TEST(WidePaths, NativeDivOutsideItsPreconditionGivesTheQuotientModulo2To64) {
  // n.hi >= d breaks Native::div's precondition. On x86-64 the fast path is one DIV instruction,
  // which would trap there; such calls must keep the general path: no trap, and the quotient
  // reduced modulo 2^64. volatile keeps the operands from being folded at compile time.
  volatile std::uint64_t hi = 7;
  volatile std::uint64_t d = 7;
  const auto r = wide::Native::div(U128{hi, 5}, d);  // (7 2^64 + 5) / 7 = 2^64 + 5/7
  EXPECT_EQ(r.quotient, 0U);
  EXPECT_EQ(r.remainder, 5U);
  hi = ~std::uint64_t{0};
  d = 2;
  const auto s = wide::Native::div(U128{hi, 0}, d);  // (2^64 - 1) 2^63 = 2^127 - 2^63
  EXPECT_EQ(s.quotient, std::uint64_t{1} << 63);
  EXPECT_EQ(s.remainder, 0U);
}

TEST(WidePaths, FixedOperatorsAgreeOnBothPaths) {
  const auto v = operands(kCount + 1, 13);
  for (std::size_t i = 0; i < kCount; ++i) {
    const auto a = static_cast<std::int64_t>(v[i]);
    const auto b = static_cast<std::int64_t>(v[i + 1]) >> (v[i] % 64);  // spread the magnitudes
    ASSERT_EQ(detail::fixed_mul<wide::Portable>(a, b), detail::fixed_mul<wide::Native>(a, b))
        << a << " * " << b;
    ASSERT_EQ(detail::fixed_div<wide::Portable>(a, b), detail::fixed_div<wide::Native>(a, b))
        << a << " / " << b;
  }
}

// Product sums: NativeProductSum (an __int128 plus a wrap count, the fast path) against
// ExactSum<3> (192-bit limbs, the exact path and the one 32-bit targets take). The operands aim at
// the places a fast path could go wrong: the int64 extremes, magnitudes near 2^62 and 2^63 (terms
// near 2^124..2^126, so that two to four of them leave the int128 range), and values with many
// trailing zeros combined with a half-ulp term (exact ties at the rounding bit, of both signs).
constexpr std::int64_t kMin = std::numeric_limits<std::int64_t>::min();
constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kTwo62 = std::int64_t{1} << 62;
constexpr std::int64_t kTwo32 = std::int64_t{1} << 32;
constexpr std::int64_t kTwo31 = std::int64_t{1} << 31;

// +-magnitude with a random sign; magnitude < 2^63.
std::int64_t with_sign(std::mt19937_64& rng, std::uint64_t magnitude) {
  const auto v = static_cast<std::int64_t>(magnitude);
  return (rng() & 1) != 0 ? -v : v;
}

std::int64_t boundary_operand(std::mt19937_64& rng) {
  static constexpr std::array<std::int64_t, 20> kEdges = {0,
                                                          1,
                                                          -1,
                                                          kMin,
                                                          kMax,
                                                          kMin + 1,
                                                          kMax - 1,
                                                          kTwo62,
                                                          -kTwo62,
                                                          kTwo62 - 1,
                                                          -kTwo62 + 1,
                                                          kTwo62 + 1,
                                                          -kTwo62 - 1,
                                                          kTwo62 + kTwo62 / 2,
                                                          -kTwo62 - kTwo62 / 2,
                                                          kTwo31,
                                                          -kTwo31,
                                                          kTwo32,
                                                          -kTwo32,
                                                          kTwo32 + 1};
  const std::uint64_t small = (rng() >> 1) >> (rng() % 64);  // any width below 2^63
  switch (rng() % 8) {
    case 0:
      return kEdges[rng() % kEdges.size()];
    case 1:  // within `small` of +-2^63
      return (rng() & 1) != 0 ? kMax - static_cast<std::int64_t>(small)
                              : kMin + static_cast<std::int64_t>(small);
    case 2:  // within `small` of +-2^62
      return ((rng() & 1) != 0 ? kTwo62 : -kTwo62) + with_sign(rng, small >> 2);
    case 3:  // random bits above a random number of trailing zeros
      return static_cast<std::int64_t>(rng() & (~std::uint64_t{0} << (rng() % 64)));
    case 4:  // a small odd number times a power of two
      return with_sign(rng, ((rng() % 256) | 1U) << (rng() % 55));
    default:
      return with_sign(rng, small);
  }
}

// A 128-bit magnitude for ProductSum::add(negative, m), including those at and above 2^127.
wide::U128 boundary_magnitude(std::mt19937_64& rng) {
  switch (rng() % 4) {
    case 0:
      return {~std::uint64_t{0} >> (rng() % 2), ~std::uint64_t{0}};  // 2^128 - 1 or 2^127 - 1
    case 1:
      return {std::uint64_t{1} << 63, rng() % 2};  // 2^127, 2^127 + 1
    case 2:
      return {0, std::uint64_t{1} << (rng() % 64)};
    default:
      return {rng() >> (rng() % 64), rng()};
  }
}

constexpr std::array<unsigned, 13> kShifts = {1, 2, 30, 31, 32, 33, 34, 62, 63, 64, 65, 96, 128};

// Fails unless the native sum and the exact sum agree on everything a caller can observe.
::testing::AssertionResult same_sum(const detail::NativeProductSum& native,
                                    const detail::ExactSum<3>& exact) {
  if (native.negative() != exact.negative()) return ::testing::AssertionFailure() << "negative()";
  if (native.is_zero() != exact.is_zero()) return ::testing::AssertionFailure() << "is_zero()";
  if (native.fits_128() != exact.fits_128()) return ::testing::AssertionFailure() << "fits_128()";
  if (exact.fits_128() && !(native.magnitude_128() == exact.magnitude_128()))
    return ::testing::AssertionFailure() << "magnitude_128()";
  for (const unsigned shift : kShifts) {
    const std::int64_t got = native.round_to_raw(shift);
    const std::int64_t want = exact.round_to_raw(shift);
    if (got != want) {
      return ::testing::AssertionFailure()
             << "round_to_raw(" << shift << "): native " << got << ", exact " << want;
    }
  }
  if (native.to_fixed() != exact.to_fixed()) return ::testing::AssertionFailure() << "to_fixed()";
  // A base added before the one rounding (Vec3Sum's fused multiply-add): odd and even bases flip
  // which way a tie goes, and bases near the int64 ends bring sums beyond int64 back into range
  // or push sums inside it out.
  for (const std::int64_t base :
       {std::int64_t{0}, std::int64_t{1}, std::int64_t{-1}, std::int64_t{2}, std::int64_t{1} << 32,
        kMax, kMax - 1, kMin, kMin + 1, kMax / 3, kMin / 3}) {
    if (native.to_fixed_plus(base) != exact.to_fixed_plus(base))
      return ::testing::AssertionFailure()
             << "to_fixed_plus(" << base << "): native " << native.to_fixed_plus(base).raw()
             << ", exact " << exact.to_fixed_plus(base).raw();
  }
  return ::testing::AssertionSuccess();
}

// How often the generator reached the cases that matter, read off the exact sum.
struct Coverage {
  std::size_t beyond_int128 = 0;  // |sum| >= 2^127: the native accumulator has wrapped
  std::size_t ties = 0;           // exactly half an ulp at shift 32, positive sums
  std::size_t negative_ties = 0;  // the same, negative sums

  void record(const detail::ExactSum<3>& exact) {
    const auto m = exact.magnitude_words();
    if (m[2] != 0 || (m[1] >> 63) != 0) ++beyond_int128;
    if ((m[0] & 0xFFFFFFFFU) == 0x80000000U) ++(exact.negative() ? negative_ties : ties);
  }
};

TEST(ProductSumPaths, NativeEqualsExactOnBoundaryOperands) {
  std::mt19937_64 rng(15);
  Coverage seen;
  const std::size_t count = test::scaled(1'000'000);
  for (std::size_t n = 0; n < count; ++n) {
    detail::NativeProductSum native;
    detail::ExactSum<3> exact;
    // Ties: terms that are multiples of 2^64 (both operands with 32 trailing zeros) and one
    // half-ulp term +-odd * 2^(s-1) make an exact tie at shift s.
    const bool tie_case = rng() % 4 == 0;
    const unsigned tie_shift = (rng() & 1) != 0 ? 32 : kShifts[rng() % 9];  // shifts up to 63
    const std::size_t terms = 1 + rng() % 5;
    for (std::size_t t = 0; t < terms; ++t) {
      std::int64_t a = boundary_operand(rng);
      std::int64_t b = boundary_operand(rng);
      if (tie_case) {
        a = static_cast<std::int64_t>(static_cast<std::uint64_t>(a) & ~std::uint64_t{0xFFFFFFFF});
        b = static_cast<std::int64_t>(static_cast<std::uint64_t>(b) & ~std::uint64_t{0xFFFFFFFF});
      }
      switch (rng() % 8) {
        case 0:
        case 1:
        case 2:
          native.add_product(a, b);
          exact.add_product(a, b);
          break;
        case 3:
        case 4:
        case 5:
          native.sub_product(a, b);
          exact.sub_product(a, b);
          break;
        case 6: {
          const auto shift = static_cast<unsigned>(tie_case ? 32 + rng() % 32 : rng() % 64);
          native.add_scaled(a, shift);
          exact.add_scaled(a, shift);
          break;
        }
        default: {
          const bool negative = (rng() & 1) != 0;
          wide::U128 m = boundary_magnitude(rng);
          if (tie_case) m.lo = 0;
          native.add(negative, m);
          exact.add(negative, m);
          break;
        }
      }
      ASSERT_TRUE(same_sum(native, exact)) << "case " << n << ", after term " << t;
    }
    if (tie_case) {
      const std::int64_t odd = with_sign(rng, ((rng() >> 1) >> (rng() % 64)) | 1U);
      native.add_scaled(odd, tie_shift - 1);
      exact.add_scaled(odd, tie_shift - 1);
      ASSERT_TRUE(same_sum(native, exact)) << "case " << n << ", tie at shift " << tie_shift;
    }
    seen.record(exact);
  }
  // The generator must actually reach the boundaries (a few percent of the cases each).
  EXPECT_GT(seen.beyond_int128, count / 100) << "sums beyond the int128 range";
  EXPECT_GT(seen.ties, count / 100) << "positive ties at shift 32";
  EXPECT_GT(seen.negative_ties, count / 100) << "negative ties at shift 32";
}

TEST(ProductSumPaths, EveryWrapOfTheNativeSumIsCounted) {
  // Sums that leave the int128 range and come back, upwards and downwards, then cross zero.
  detail::NativeProductSum native;
  detail::ExactSum<3> exact;
  const std::array<std::array<std::int64_t, 2>, 6> steps = {
      {{kMin, kMin}, {kMin, kMin}, {kMin, kMin}, {kMin, kMax}, {kMax, kMax}, {1, 1}}};
  for (int direction = 0; direction < 2; ++direction) {
    for (const auto& s : steps) {
      if (direction == 0) {
        native.add_product(s[0], s[1]);
        exact.add_product(s[0], s[1]);
      } else {
        native.sub_product(s[0], s[1]);
        exact.sub_product(s[0], s[1]);
      }
      ASSERT_TRUE(same_sum(native, exact)) << "direction " << direction;
    }
  }
  for (int i = 0; i < 8; ++i) {  // back through zero and out the negative side
    native.sub_product(kMin, kMin);
    exact.sub_product(kMin, kMin);
    ASSERT_TRUE(same_sum(native, exact)) << "step " << i;
  }
}

TEST(ProductSumPaths, RoundingAtTheEdgesOfTheInt64Range) {
  // base * 2^shift + delta for results next to INT64_MAX and INT64_MIN: exact ties, one below and
  // one above, where rounding up would leave the range (and so must saturate) or ties to even keeps
  // INT64_MIN.
  for (const unsigned shift : {1U, 31U, 32U, 33U, 63U}) {
    const std::int64_t half = std::int64_t{1} << (shift - 1);
    for (const std::int64_t base : {kMax, kMax - 1, kMin, kMin + 1}) {
      for (const std::int64_t delta :
           {-half - 1, -half, -half + 1, std::int64_t{-1}, std::int64_t{0}, std::int64_t{1},
            half - 1, half, half + 1}) {
        detail::NativeProductSum native;
        detail::ExactSum<3> exact;
        native.add_scaled(base, shift);
        exact.add_scaled(base, shift);
        native.add_scaled(delta, 0);
        exact.add_scaled(delta, 0);
        ASSERT_TRUE(same_sum(native, exact)) << base << " * 2^" << shift << " + " << delta;
      }
    }
  }
}

TEST(ProductSumPaths, ABaseBringsASumBeyondInt64BackIntoRange) {
  // +-2^95 alone rounds to +-2^63, one past the int64 range at the top; a base of the other sign
  // brings it back: (-2^63 2^32 + 2^95) / 2^32 = 0. Nearby sums and exact ties (+-2^31 off) check
  // the rounding there against ExactSum, for every base same_sum tries.
  const std::int64_t half = std::int64_t{1} << 31;
  for (const std::int64_t sign : {1, -1}) {
    for (const std::int64_t delta :
         {-half - 1, -half, -half + 1, std::int64_t{0}, half - 1, half, half + 1, 3 * half}) {
      detail::NativeProductSum native;
      detail::ExactSum<3> exact;
      native.add_product(sign << 62, std::int64_t{1} << 33);
      exact.add_product(sign << 62, std::int64_t{1} << 33);
      native.add_scaled(delta, 0);
      exact.add_scaled(delta, 0);
      ASSERT_TRUE(same_sum(native, exact)) << sign << " 2^95 + " << delta;
    }
  }
  detail::NativeProductSum up;
  up.add_product(std::int64_t{1} << 62, std::int64_t{1} << 33);
  EXPECT_EQ(up.to_fixed_plus(kMin).raw(), 0);
  EXPECT_EQ(up.to_fixed_plus(kMin + 5).raw(), 5);
  EXPECT_EQ(up.to_fixed_plus(0), Fixed::max());
}

TEST(ProductSumPaths, RoundingNextToTheInt128Maximum) {
  // Sums just below 2^127 that the native form still holds without a wrap: adding the rounding
  // bias to them leaves the int128 range, and every shift must still saturate (as ExactSum does).
  // 2^126 + (2^63 - 1)^2 + (2^63 - 1) 2 = 2^127 - 1, then minus small and large amounts.
  for (const std::int64_t below :
       {std::int64_t{0}, std::int64_t{1}, std::int64_t{2}, kMax / 2, kMax - 1, kMax}) {
    detail::NativeProductSum native;
    detail::ExactSum<3> exact;
    native.add_product(kMin, kMin);
    exact.add_product(kMin, kMin);
    native.add_product(kMax, kMax);
    exact.add_product(kMax, kMax);
    native.add_scaled(kMax, 1);
    exact.add_scaled(kMax, 1);
    native.add_scaled(-below, 0);
    exact.add_scaled(-below, 0);
    ASSERT_FALSE(native.negative()) << below;
    ASSERT_TRUE(same_sum(native, exact)) << "2^127 - 1 - " << below;
    for (const unsigned shift : {1U, 32U, 63U})
      EXPECT_EQ(native.round_to_raw(shift), kMax) << "2^127 - 1 - " << below << ", shift " << shift;
  }
}

Fixed raw_fixed(std::int64_t r) {
  return Fixed::from_raw(r);
}

// The exact a . b rounded once: the reference for dot, length_squared and Mat3 * Vec3.
Fixed exact_dot(Vec3 a, Vec3 b) {
  detail::ExactSum<3> s;
  s.add_product(a.x.raw(), b.x.raw());
  s.add_product(a.y.raw(), b.y.raw());
  s.add_product(a.z.raw(), b.z.raw());
  return s.to_fixed();
}

// The exact p q - r t rounded once: the reference for each cross product component.
Fixed exact_cross_component(Fixed p, Fixed q, Fixed r, Fixed t) {
  detail::ExactSum<3> s;
  s.add_product(p.raw(), q.raw());
  s.sub_product(r.raw(), t.raw());
  return s.to_fixed();
}

Vec3 boundary_vec3(std::mt19937_64& rng) {
  return {raw_fixed(boundary_operand(rng)), raw_fixed(boundary_operand(rng)),
          raw_fixed(boundary_operand(rng))};
}

TEST(ProductSumPaths, VectorProductsEqualTheExactSumRoundedOnce) {
  std::mt19937_64 rng(16);
  for (std::size_t n = 0, count = test::scaled(1'000'000); n < count; ++n) {
    const Vec3 a = boundary_vec3(rng);
    const Vec3 b = boundary_vec3(rng);
    ASSERT_EQ(dot(a, b), exact_dot(a, b))
        << a.x.raw() << " " << a.y.raw() << " " << a.z.raw() << " . " << b.x.raw() << " "
        << b.y.raw() << " " << b.z.raw();
    ASSERT_EQ(length_squared(a), exact_dot(a, a));
    const Vec3 c = cross(a, b);
    ASSERT_EQ(c.x, exact_cross_component(a.y, b.z, a.z, b.y));
    ASSERT_EQ(c.y, exact_cross_component(a.z, b.x, a.x, b.z));
    ASSERT_EQ(c.z, exact_cross_component(a.x, b.y, a.y, b.x));
    ASSERT_EQ(dot(Vec2{a.x, a.y}, Vec2{b.x, b.y}), exact_dot({a.x, a.y, {}}, {b.x, b.y, {}}));
    ASSERT_EQ(cross(Vec2{a.x, a.y}, Vec2{b.x, b.y}), exact_cross_component(a.x, b.y, a.y, b.x));
    const Mat3 m{{a, b, boundary_vec3(rng)}};
    const Vec3 v = boundary_vec3(rng);
    ASSERT_EQ(m * v,
              (Vec3{exact_dot(m.rows[0], v), exact_dot(m.rows[1], v), exact_dot(m.rows[2], v)}));
  }
}

TEST(ProductSumPaths, FixedMulAgreesOnBothPathsOnBoundaryOperands) {
  std::mt19937_64 rng(17);
  for (std::size_t n = 0, count = test::scaled(4'000'000); n < count; ++n) {
    const std::int64_t a = boundary_operand(rng);
    const std::int64_t b = boundary_operand(rng);
    ASSERT_EQ(detail::fixed_mul<wide::Portable>(a, b), detail::fixed_mul<wide::Native>(a, b))
        << a << " * " << b;
  }
}
#else
TEST(WidePaths, NativeIsPortableWithoutInt128) {
  static_assert(std::is_same_v<wide::Native, wide::Portable>);
  static_assert(std::is_same_v<detail::ProductSum, detail::ExactSum<3>>);
  SUCCEED() << "no __int128 on this target: the bit-serial tests below check the portable path";
}
#endif

TEST(WidePaths, PortableAgreesWithBitSerialReference) {
  const auto v = operands(400'001, 14);
  for (std::size_t i = 0; i + 1 < v.size(); ++i) {
    ASSERT_EQ(wide::Portable::mul(v[i], v[i + 1]), serial_mul(v[i], v[i + 1]));
    const std::uint64_t d = v[i + 1] == 0 ? 1 : v[i + 1];
    const U128 n{v[i] % d, v[(i * 7 + 3) % v.size()]};
    const auto p = wide::Portable::div(n, d);
    const auto s = serial_div(n, d);
    ASSERT_EQ(p.quotient, s.quotient) << n.hi << ":" << n.lo << " / " << d;
    ASSERT_EQ(p.remainder, s.remainder) << n.hi << ":" << n.lo << " / " << d;
  }
}

TEST(WidePaths, DivisionCornerCases) {
  // Largest quotient: (d - 1) * 2^64 + (2^64 - 1) divided by d.
  for (const std::uint64_t d :
       {std::uint64_t{1}, std::uint64_t{3}, std::uint64_t{1} << 63, ~std::uint64_t{0}}) {
    const U128 n{d - 1, ~std::uint64_t{0}};
    const auto p = wide::Portable::div(n, d);
    EXPECT_EQ(p.quotient, ~std::uint64_t{0});
    EXPECT_EQ(p.remainder, d - 1);
    // Reconstruct: q * d + r == n.
    EXPECT_EQ(wide::add(wide::Portable::mul(p.quotient, d), U128{0, p.remainder}), n);
  }
}

}  // namespace
}  // namespace detsim

// The two 128-bit paths: Portable (plain 64-bit C++, used where the compiler has no __int128) and
// Native (__int128). Both are compiled in every build; they must agree bit for bit, and Portable
// must also agree with a bit-serial reference that shares no code with either.
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/wide.hpp>

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
#else
TEST(WidePaths, NativeIsPortableWithoutInt128) {
  static_assert(std::is_same_v<wide::Native, wide::Portable>);
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

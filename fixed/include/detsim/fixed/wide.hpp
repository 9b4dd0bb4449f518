// 128-bit integer helpers for the fixed-point layer.
//
// Every Q32.32 product needs 64x64->128 bits and every quotient a 128/64 division. Compilers for
// 64-bit targets offer `unsigned __int128`; 32-bit targets (i686, armhf, mips) do not. Both paths
// are compiled in every build: `Portable` is plain 64-bit C++ and `Native` uses __int128 where the
// compiler has it (and is an alias of `Portable` where it does not). The arithmetic in fixed.hpp is
// written once, as templates over these two policies, so that the two paths cannot drift apart, and
// a test compares them bit for bit.
#pragma once

#include <bit>
#include <cstdint>
#include <type_traits>

#if defined(__SIZEOF_INT128__) && !defined(DETSIM_NO_INT128)
#define DETSIM_HAS_INT128 1
#else
#define DETSIM_HAS_INT128 0
#endif

namespace detsim::wide {

/// An unsigned 128-bit value as two 64-bit halves.
struct U128 {
  std::uint64_t hi = 0;
  std::uint64_t lo = 0;
  friend constexpr bool operator==(U128, U128) = default;
};

/// Quotient and remainder of a 128/64 division.
struct DivResult {
  std::uint64_t quotient = 0;
  std::uint64_t remainder = 0;
};

constexpr U128 add(U128 a, U128 b) noexcept {
  const std::uint64_t lo = a.lo + b.lo;
  return {a.hi + b.hi + (lo < a.lo ? 1U : 0U), lo};
}

constexpr U128 sub(U128 a, U128 b) noexcept {
  return {a.hi - b.hi - (a.lo < b.lo ? 1U : 0U), a.lo - b.lo};
}

constexpr bool less(U128 a, U128 b) noexcept {
  return a.hi < b.hi || (a.hi == b.hi && a.lo < b.lo);
}

/// Logical shift left by 0..127.
constexpr U128 shl(U128 a, unsigned n) noexcept {
  if (n == 0) return a;
  if (n >= 64) return {a.lo << (n - 64), 0};
  return {(a.hi << n) | (a.lo >> (64 - n)), a.lo << n};
}

/// Logical shift right by 0..127.
constexpr U128 shr(U128 a, unsigned n) noexcept {
  if (n == 0) return a;
  if (n >= 64) return {0, a.hi >> (n - 64)};
  return {a.hi >> n, (a.lo >> n) | (a.hi << (64 - n))};
}

/// Two's-complement negation.
constexpr U128 negate(U128 a) noexcept {
  return sub(U128{0, 0}, a);
}

/// Plain 64-bit C++: schoolbook multiplication on 32-bit limbs and Knuth's algorithm D with two
/// 32-bit quotient digits (Hacker's Delight, "divlu"). Valid on every target.
struct Portable {
  static constexpr U128 mul(std::uint64_t a, std::uint64_t b) noexcept {
    const std::uint64_t a_lo = a & 0xFFFFFFFFU;
    const std::uint64_t a_hi = a >> 32;
    const std::uint64_t b_lo = b & 0xFFFFFFFFU;
    const std::uint64_t b_hi = b >> 32;
    const std::uint64_t lo_lo = a_lo * b_lo;
    const std::uint64_t hi_lo = a_hi * b_lo;
    const std::uint64_t lo_hi = a_lo * b_hi;
    const std::uint64_t hi_hi = a_hi * b_hi;
    // The middle column cannot overflow: (2^32-1)^2 + 2 (2^32-1) < 2^64.
    const std::uint64_t middle = (lo_lo >> 32) + (hi_lo & 0xFFFFFFFFU) + lo_hi;
    return {hi_hi + (hi_lo >> 32) + (middle >> 32), (middle << 32) | (lo_lo & 0xFFFFFFFFU)};
  }

  /// Requires n.hi < d (so the quotient fits in 64 bits); d != 0 follows.
  static constexpr DivResult div(U128 n, std::uint64_t d) noexcept {
    constexpr std::uint64_t base = std::uint64_t{1} << 32;
    const int s = std::countl_zero(d);
    d <<= s;
    const std::uint64_t d_hi = d >> 32;
    const std::uint64_t d_lo = d & 0xFFFFFFFFU;
    const U128 nn = shl(n, static_cast<unsigned>(s));
    const std::uint64_t n32 = nn.hi;
    const std::uint64_t n1 = nn.lo >> 32;
    const std::uint64_t n0 = nn.lo & 0xFFFFFFFFU;

    std::uint64_t q1 = n32 / d_hi;
    std::uint64_t r = n32 - q1 * d_hi;
    while (q1 >= base || q1 * d_lo > ((r << 32) | n1)) {
      --q1;
      r += d_hi;
      if (r >= base) break;
    }
    const std::uint64_t n21 = (n32 << 32) + n1 - q1 * d;  // modulo 2^64, exact by construction

    std::uint64_t q0 = n21 / d_hi;
    r = n21 - q0 * d_hi;
    while (q0 >= base || q0 * d_lo > ((r << 32) | n0)) {
      --q0;
      r += d_hi;
      if (r >= base) break;
    }
    const std::uint64_t rem = ((n21 << 32) + n0 - q0 * d) >> s;
    return {(q1 << 32) | q0, rem};
  }
};

#if DETSIM_HAS_INT128
__extension__ using uint128_t = unsigned __int128;
__extension__ using int128_t = __int128;

/// The compiler's 128-bit integers (a single widening multiply on 64-bit targets).
struct Native {
  static constexpr U128 mul(std::uint64_t a, std::uint64_t b) noexcept {
    const uint128_t p = static_cast<uint128_t>(a) * b;
    return {static_cast<std::uint64_t>(p >> 64), static_cast<std::uint64_t>(p)};
  }

  /// Requires n.hi < d, so that the quotient fits in 64 bits.
  static constexpr DivResult div(U128 n, std::uint64_t d) noexcept {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
    // x86-64 divides 128 by 64 bits in one instruction, but compilers cannot know that the
    // quotient fits and call a general 128/128 routine instead (libgcc's __udivti3), which costs
    // as much again around the same instruction. The instruction traps when the quotient does not
    // fit, so that case (a broken precondition) keeps the compiler's path and its result.
    if (!std::is_constant_evaluated() && n.hi < d) [[likely]] {
      std::uint64_t quotient = 0;
      std::uint64_t remainder = 0;
      __asm__("divq %4" : "=a"(quotient), "=d"(remainder) : "a"(n.lo), "d"(n.hi), "rm"(d) : "cc");
      return {quotient, remainder};
    }
#endif
    const uint128_t num = (static_cast<uint128_t>(n.hi) << 64) | n.lo;
    const auto q = static_cast<std::uint64_t>(num / d);
    return {q, n.lo - q * d};
  }
};
#else
using Native = Portable;
#endif

/// The path used by Fixed's operators.
using Default = Native;

}  // namespace detsim::wide

// Exact sums of Q32.32 products, rounded once.
//
// A dot product of Q32.32 vectors is a sum of 128-bit products (each a Q64.64 value). Rounding
// every product to Q32.32 before adding would round up to four times and would saturate whenever a
// partial sum leaves the Fixed range even though the total does not. ExactSum instead keeps the
// whole sum as a two's-complement integer of 64 * Limbs bits and rounds once at the end, to nearest
// with ties to even, saturating to the Fixed range. Three limbs hold any sum of up to 2^64 products
// of two raws; four limbs hold sums of products of three raws (determinants, R I R^T).
//
// ExactSum is the portable definition. On targets with __int128, ProductSum is NativeProductSum
// instead: the same exact value held as an __int128 plus a wrap count, which is several times
// faster and gives bit-identical results (the slow limb path remains its fallback and reference).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/wide.hpp>

namespace detsim::detail {

template <std::size_t Limbs>
class ExactSum {
  static_assert(Limbs >= 2, "an exact sum needs at least 128 bits");

 public:
  /// Little-endian 64-bit limbs.
  using Words = std::array<std::uint64_t, Limbs>;

  /// Adds m (or subtracts it when `negative`); m is an unsigned magnitude of M <= Limbs limbs. The
  /// caller keeps the true sum inside the signed range, which the limb counts above guarantee.
  template <std::size_t M>
  constexpr void add(bool negative, const std::array<std::uint64_t, M>& m) noexcept {
    static_assert(M <= Limbs);
    // Branch-free (the sign of a product is unpredictable): adding -m is adding ~m + 1 over all
    // limbs, with the limbs above m's all ones.
    const std::uint64_t flip = negative ? ~std::uint64_t{0} : 0;
    std::uint64_t carry = negative ? 1U : 0U;
    for (std::size_t i = 0; i < Limbs; ++i) {
      const std::uint64_t mi = (i < M ? m[i] : 0) ^ flip;
      const std::uint64_t s = limb_[i] + mi;
      const std::uint64_t s2 = s + carry;
      carry = (s < mi ? 1U : 0U) | (s2 < carry ? 1U : 0U);
      limb_[i] = s2;
    }
  }

  constexpr void add(bool negative, wide::U128 m) noexcept {
    add(negative, std::array<std::uint64_t, 2>{m.lo, m.hi});
  }

  /// Adds a * b (raw times raw: a Q64.64 term).
  constexpr void add_product(std::int64_t a, std::int64_t b) noexcept {
    add((a < 0) != (b < 0), wide::Default::mul(magnitude(a), magnitude(b)));
  }

  /// Subtracts a * b.
  constexpr void sub_product(std::int64_t a, std::int64_t b) noexcept {
    add((a < 0) == (b < 0), wide::Default::mul(magnitude(a), magnitude(b)));
  }

  /// Adds (negative ? -m : m) * c for a 128-bit magnitude m: up to 192 bits.
  constexpr void add_product(bool negative, wide::U128 m, std::int64_t c) noexcept {
    const std::uint64_t cm = magnitude(c);
    const wide::U128 lo = wide::Default::mul(m.lo, cm);
    const wide::U128 hi = wide::Default::mul(m.hi, cm);
    const std::uint64_t mid = lo.hi + hi.lo;
    // m * c < 2^192, so the top limb cannot overflow.
    add(negative != (c < 0),
        std::array<std::uint64_t, 3>{lo.lo, mid, hi.hi + (mid < lo.hi ? 1U : 0U)});
  }

  /// Adds a * b * c (a Q96.96 term).
  constexpr void add_product(std::int64_t a, std::int64_t b, std::int64_t c) noexcept {
    add_product((a < 0) != (b < 0), wide::Default::mul(magnitude(a), magnitude(b)), c);
  }

  /// Subtracts a * b * c.
  constexpr void sub_product(std::int64_t a, std::int64_t b, std::int64_t c) noexcept {
    add_product((a < 0) == (b < 0), wide::Default::mul(magnitude(a), magnitude(b)), c);
  }

  /// Adds a * 2^shift, shift < 64.
  constexpr void add_scaled(std::int64_t a, unsigned shift) noexcept {
    add(a < 0, wide::shl(wide::U128{0, magnitude(a)}, shift));
  }

  [[nodiscard]] constexpr bool negative() const noexcept { return (limb_[Limbs - 1] >> 63) != 0; }

  [[nodiscard]] constexpr bool is_zero() const noexcept {
    for (const std::uint64_t w : limb_)
      if (w != 0) return false;
    return true;
  }

  /// |sum| as little-endian limbs.
  [[nodiscard]] constexpr Words magnitude_words() const noexcept {
    if (!negative()) return limb_;
    Words m{};
    std::uint64_t carry = 1;
    for (std::size_t i = 0; i < Limbs; ++i) {
      m[i] = ~limb_[i] + carry;
      carry = (carry != 0 && m[i] == 0) ? 1U : 0U;
    }
    return m;
  }

  /// |sum| when it fits in 128 bits (check with fits_128 first).
  [[nodiscard]] constexpr wide::U128 magnitude_128() const noexcept {
    const Words m = magnitude_words();
    return {m[1], m[0]};
  }

  [[nodiscard]] constexpr bool fits_128() const noexcept {
    const Words m = magnitude_words();
    for (std::size_t i = 2; i < Limbs; ++i)
      if (m[i] != 0) return false;
    return true;
  }

  /// sum / 2^shift rounded to nearest, ties to even, saturated to the int64 range. 1 <= shift and
  /// shift + 64 <= 64 * Limbs. Rounding the magnitude and then applying the sign equals rounding
  /// the signed value, because ties to even is symmetric.
  [[nodiscard]] constexpr std::int64_t round_to_raw(unsigned shift) const noexcept {
    const bool neg = negative();
    const Words m = magnitude_words();
    const std::size_t word = shift / 64;
    const unsigned bit = shift % 64;
    std::uint64_t q = m[word] >> bit;
    bool overflow = false;
    if (bit != 0 && word + 1 < Limbs) {
      q |= m[word + 1] << (64 - bit);
      overflow = (m[word + 1] >> bit) != 0;
    } else if (bit == 0 && word + 1 < Limbs) {
      overflow = m[word + 1] != 0;
    }
    for (std::size_t i = word + 2; i < Limbs; ++i)
      overflow = overflow || m[i] != 0;
    if (overflow) return neg ? raw_min : raw_max;

    const std::size_t half_word = (shift - 1) / 64;
    const unsigned half_bit = (shift - 1) % 64;
    const bool half = ((m[half_word] >> half_bit) & 1U) != 0;
    bool sticky = (m[half_word] & ((std::uint64_t{1} << half_bit) - 1)) != 0;
    for (std::size_t i = 0; i < half_word; ++i)
      sticky = sticky || m[i] != 0;
    const bool up = half && (sticky || (q & 1U) != 0);
    if (up && q == ~std::uint64_t{0}) return neg ? raw_min : raw_max;
    return signed_saturate(neg, q + (up ? 1U : 0U));
  }

  /// The sum of Q64.64 terms rounded to Fixed.
  [[nodiscard]] constexpr Fixed to_fixed() const noexcept {
    return Fixed::from_raw(round_to_raw(Fixed::fraction_bits));
  }

  /// base + sum / 2^32 rounded once to Fixed: to_fixed() of the sum with base * 2^32 added.
  [[nodiscard]] constexpr Fixed to_fixed_plus(std::int64_t base) const noexcept {
    ExactSum with_base = *this;
    with_base.add_scaled(base, Fixed::fraction_bits);
    return with_base.to_fixed();
  }

 private:
  Words limb_{};
};

#if DETSIM_HAS_INT128
/// An exact sum of Q64.64 terms for 64-bit targets: the same value, and so the same rounded result,
/// as ExactSum<3>, in the form the hardware adds fastest (a widening multiply and an add with carry
/// per term, small enough for dot and cross to inline). Every term a * b of two raws fits in a
/// signed 128-bit integer (|a b| <= 2^126), so the sum is kept as `acc_ + wraps_ * 2^128`: an
/// __int128 that wraps modulo 2^128 plus a count of its wraps. A wrap needs partial sums of 2^127
/// or more, i.e. several terms near 2^126 (raws near +-2^63); with wraps_ == 0 the value is acc_
/// and rounds with a few 64-bit operations. Any other state, and any shift above 63, goes to the
/// out-of-line ExactSum<3> path. Determinism does not depend on which path runs: the result is
/// defined as the exactly rounded value, both paths compute exactly that, and a differential test
/// (tests/fixed_wide_test.cpp) compares them on boundary operands.
class NativeProductSum {
 public:
  using int128 = wide::int128_t;

  constexpr NativeProductSum() noexcept = default;

  /// Adds m (or subtracts it when `negative`) for an unsigned 128-bit magnitude m.
  constexpr void add(bool negative, wide::U128 m) noexcept {
    // As a signed value the bits of m are m, or m - 2^128 when m >= 2^127: count that 2^128 too.
    const auto term = static_cast<int128>((static_cast<wide::uint128_t>(m.hi) << 64) | m.lo);
    if (negative) {
      sub_term(term);
      if (term < 0) --wraps_;
    } else {
      add_term(term);
      if (term < 0) ++wraps_;
    }
  }

  /// Adds a * b (raw times raw: a Q64.64 term).
  constexpr void add_product(std::int64_t a, std::int64_t b) noexcept {
    add_term(static_cast<int128>(a) * b);
  }

  /// Subtracts a * b.
  constexpr void sub_product(std::int64_t a, std::int64_t b) noexcept {
    sub_term(static_cast<int128>(a) * b);
  }

  /// Adds a * 2^shift, shift < 64.
  constexpr void add_scaled(std::int64_t a, unsigned shift) noexcept {
    add_term(static_cast<int128>(a) * static_cast<int128>(std::uint64_t{1} << shift));
  }

  [[nodiscard]] constexpr bool negative() const noexcept {
    return wraps_ < 0 || (wraps_ == 0 && acc_ < 0);
  }

  [[nodiscard]] constexpr bool is_zero() const noexcept { return wraps_ == 0 && acc_ == 0; }

  /// |sum| < 2^128. A wrapped sum has |sum| >= 2^127, so this asks ExactSum only then.
  [[nodiscard]] constexpr bool fits_128() const noexcept {
    return wraps_ == 0 || exact().fits_128();
  }

  /// |sum| when it fits in 128 bits (check with fits_128 first): |sum| modulo 2^128, which is acc_
  /// or its negation as an unsigned value whatever the wrap count.
  [[nodiscard]] constexpr wide::U128 magnitude_128() const noexcept {
    const auto bits = static_cast<wide::uint128_t>(acc_);
    const wide::uint128_t m = negative() ? 0U - bits : bits;
    return {static_cast<std::uint64_t>(m >> 64), static_cast<std::uint64_t>(m)};
  }

  /// sum / 2^shift rounded to nearest, ties to even, saturated to the int64 range; 1 <= shift <=
  /// 128, exactly as ExactSum<3>::round_to_raw.
  [[nodiscard]] constexpr std::int64_t round_to_raw(unsigned shift) const noexcept {
    if (wraps_ == 0 && shift < 64) [[likely]]
      return round_shift_saturate(acc_, shift);
    return round_exact(acc_, wraps_, shift);
  }

  /// The sum of Q64.64 terms rounded to Fixed.
  [[nodiscard]] constexpr Fixed to_fixed() const noexcept {
    return Fixed::from_raw(round_to_raw(Fixed::fraction_bits));
  }

  /// base + sum / 2^32 rounded once to Fixed, as ExactSum<3>::to_fixed_plus, without forming the
  /// 128-bit term base * 2^32 (a fused multiply-add's addend). Its low 32 bits are zero, so bit 32
  /// of the whole sum, the kept value's lowest bit that breaks a tie, is bit 0 of base xor bit 32
  /// of acc_, and floor((base 2^32 + acc_ + bias) / 2^32) = base + floor((acc_ + bias) / 2^32) =
  /// base + q. When q fits in 64 bits the result is base + q, saturated; other sums (q beyond
  /// int64, which base can still bring back, or a wrapped acc_) take the exact path.
  [[nodiscard, gnu::always_inline]] constexpr Fixed to_fixed_plus(
      std::int64_t base) const noexcept {
    if (wraps_ == 0) [[likely]] {
      const auto low = static_cast<std::uint64_t>(acc_);
      const std::uint64_t bias =
          0x7FFFFFFFU + (((low >> 32) ^ static_cast<std::uint64_t>(base)) & 1U);
      int128 w = 0;
      if (!__builtin_add_overflow(acc_, static_cast<int128>(bias), &w)) [[likely]] {
        const auto hi = static_cast<std::uint64_t>(w >> 64);
        if (static_cast<std::int64_t>(hi << 32) >> 32 == static_cast<std::int64_t>(hi)) [[likely]] {
          const auto q =
              static_cast<std::int64_t>((static_cast<std::uint64_t>(w) >> 32) | (hi << 32));
          std::int64_t sum = 0;
          if (!__builtin_add_overflow(base, q, &sum)) return Fixed::from_raw(sum);
          return q < 0 ? Fixed::min() : Fixed::max();  // base and q share the sign of the excess
        }
      }
    }
    return plus_exact(acc_, wraps_, base);
  }

  /// The same sum as an ExactSum<3> (the reference the fast path must agree with).
  [[nodiscard]] constexpr ExactSum<3> exact() const noexcept {
    // Two's complement over 192 bits: acc_ sign-extended, plus wraps_ in the top limb.
    const auto bits = static_cast<wide::uint128_t>(acc_);
    const std::uint64_t sign = acc_ < 0 ? ~std::uint64_t{0} : 0U;
    ExactSum<3> e;
    e.add(false, std::array<std::uint64_t, 3>{static_cast<std::uint64_t>(bits),
                                              static_cast<std::uint64_t>(bits >> 64),
                                              sign + static_cast<std::uint64_t>(wraps_)});
    return e;
  }

 private:
  // __builtin_{add,sub}_overflow wrap the 128-bit sum and report it instead of overflowing (which
  // would be undefined); the carry out of bit 127 goes into wraps_.
  constexpr void add_term(int128 term) noexcept {
    if (__builtin_add_overflow(acc_, term, &acc_)) [[unlikely]]
      wraps_ += term < 0 ? -1 : 1;
  }
  constexpr void sub_term(int128 term) noexcept {
    if (__builtin_sub_overflow(acc_, term, &acc_)) [[unlikely]]
      wraps_ += term < 0 ? 1 : -1;
  }

  // The rare paths take the sum by value: a member call would need the sum in memory, and the
  // compiler would store every sum there on the fast path too.
  [[gnu::cold, gnu::noinline]] static constexpr std::int64_t round_exact(int128 acc,
                                                                         std::int64_t wraps,
                                                                         unsigned shift) noexcept {
    return NativeProductSum{acc, wraps}.exact().round_to_raw(shift);
  }

  [[gnu::cold, gnu::noinline]] static constexpr Fixed plus_exact(int128 acc, std::int64_t wraps,
                                                                 std::int64_t base) noexcept {
    return NativeProductSum{acc, wraps}.exact().to_fixed_plus(base);
  }

  constexpr NativeProductSum(int128 acc, std::int64_t wraps) noexcept : acc_(acc), wraps_(wraps) {}

  int128 acc_ = 0;
  std::int64_t wraps_ = 0;
};

/// The sum of products used by dot and cross products: exact for any number of terms that matters.
using ProductSum = NativeProductSum;
#else
/// The sum of products used by dot and cross products: exact for any number of terms that matters.
using ProductSum = ExactSum<3>;
#endif
/// The sum of products of three raws (determinants, tensor rotation).
using TripleProductSum = ExactSum<4>;

}  // namespace detsim::detail

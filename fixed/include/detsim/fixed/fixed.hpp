// detsim::Fixed: a Q32.32 fixed-point number whose every result is defined and identical on every
// machine.
//
// Policy (docs/FIXED.md has the full table):
// - Representation: a signed 64-bit integer `raw`; the value is raw / 2^32. One ulp is 2^-32.
// - Rounding: every operation that drops bits (*, /, >>, conversions, literals, parse) rounds to
//   nearest, ties to even. There is no other rounding rule.
// - Overflow: results outside [min(), max()] saturate to the nearer extreme. -min() == max().
// - Division by zero never traps: x / 0 is max() for x > 0, min() for x < 0, and 0 for 0 / 0.
// - Shifts: x << n == x * 2^n (saturating), x >> n == x / 2^n (rounded); n < 0 shifts the other
// way.
#pragma once

#include <compare>
#include <cstdint>
#include <limits>
#include <string_view>
#include <type_traits>

#include <detsim/fixed/wide.hpp>

namespace detsim {

struct ParseResult;

namespace detail {

inline constexpr int fraction_bits = 32;
inline constexpr std::int64_t raw_max = std::numeric_limits<std::int64_t>::max();
inline constexpr std::int64_t raw_min = std::numeric_limits<std::int64_t>::min();

/// |v| as an unsigned value (exact for INT64_MIN).
constexpr std::uint64_t magnitude(std::int64_t v) noexcept {
  return v < 0 ? 0U - static_cast<std::uint64_t>(v) : static_cast<std::uint64_t>(v);
}

/// Applies a sign to an unsigned magnitude and saturates to the int64 range.
constexpr std::int64_t signed_saturate(bool negative, std::uint64_t mag) noexcept {
  if (negative) {
    return mag >= (std::uint64_t{1} << 63) ? raw_min : -static_cast<std::int64_t>(mag);
  }
  return mag > static_cast<std::uint64_t>(raw_max) ? raw_max : static_cast<std::int64_t>(mag);
}

/// Rounds a 128-bit magnitude right by `shift` bits (1..64), to nearest, ties to even. The result
/// saturates to UINT64_MAX when it does not fit in 64 bits.
constexpr std::uint64_t round_shift_right(wide::U128 v, unsigned shift) noexcept {
  const wide::U128 q = wide::shr(v, shift);
  if (q.hi != 0) return ~std::uint64_t{0};
  const std::uint64_t rest = shift == 64 ? v.lo : v.lo & ((std::uint64_t{1} << shift) - 1);
  const std::uint64_t half = std::uint64_t{1} << (shift - 1);
  const bool up = rest > half || (rest == half && (q.lo & 1U) != 0);
  if (up && q.lo == ~std::uint64_t{0}) return q.lo;  // saturated anyway
  return q.lo + (up ? 1U : 0U);
}

#if DETSIM_HAS_INT128
/// v / 2^shift rounded to nearest, ties to even, saturated to the int64 range; 1 <= shift <= 63.
/// The signed form for 64-bit targets, shared by Fixed * and the native product sum. Ties to even
/// in one addition: w = v + 2^(shift-1) - 1 + (bit `shift` of v) carries into bit `shift` iff the
/// dropped bits exceed half, or equal it with the kept value odd; then floor(w / 2^shift) is the
/// rounded value, and it fits iff w's bits shift+63..127 are all equal (the high half, w / 2^64,
/// is a shift-bit signed integer). Only a v within 2^63 of the int128 maximum can make the
/// addition overflow, and its quotient saturates anyway.
constexpr std::int64_t round_shift_saturate(wide::int128_t v, unsigned shift) noexcept {
  const std::uint64_t bias =
      ((std::uint64_t{1} << (shift - 1)) - 1) + ((static_cast<std::uint64_t>(v) >> shift) & 1U);
  wide::int128_t w = 0;
  if (__builtin_add_overflow(v, static_cast<wide::int128_t>(bias), &w)) return raw_max;
  const auto lo = static_cast<std::uint64_t>(w);
  const auto hi = static_cast<std::uint64_t>(w >> 64);
  const auto high_bits = 64 - shift;
  if (static_cast<std::int64_t>(hi << high_bits) >> high_bits != static_cast<std::int64_t>(hi))
    return static_cast<std::int64_t>(hi) < 0 ? raw_min : raw_max;
  return static_cast<std::int64_t>((lo >> shift) | (hi << high_bits));
}
#endif

/// Whether min(round(sqrt(n)), raw_max) > l: the comparison of a correctly rounded, saturated root
/// (sqrt, hypot, length) with a raw value, decided without the root. For 0 <= l < raw_max,
/// round(sqrt(n)) > l iff sqrt(n) > l + 1/2 (the root of an integer is never halfway between two
/// integers), iff n > l^2 + l + 1/4, iff n > l (l + 1), as both sides are integers (and l (l + 1) <
/// 2^126 fits).
constexpr bool root_exceeds(wide::U128 n, std::int64_t l) noexcept {
  if (l < 0) return true;          // a root is >= 0
  if (l == raw_max) return false;  // and saturates at raw_max
  const auto ul = static_cast<std::uint64_t>(l);
  return wide::less(wide::Default::mul(ul, ul + 1), n);
}

template <class Ops>
constexpr std::int64_t fixed_mul(std::int64_t a, std::int64_t b) noexcept {
#if DETSIM_HAS_INT128
  if constexpr (std::is_same_v<Ops, wide::Native>) {
    // One widening signed multiply (|a b| <= 2^126 always fits), then one rounding.
    return round_shift_saturate(static_cast<wide::int128_t>(a) * b, fraction_bits);
  }
#endif
  // Portable: sign-magnitude. Round the magnitude, then apply the sign; ties to even is symmetric,
  // so this equals rounding the signed product. Tests compare the two forms bit for bit.
  const bool negative = (a < 0) != (b < 0);
  const wide::U128 product = Ops::mul(magnitude(a), magnitude(b));
  return signed_saturate(negative, round_shift_right(product, fraction_bits));
}

template <class Ops>
constexpr std::int64_t fixed_div(std::int64_t a, std::int64_t b) noexcept {
  if (b == 0) return a > 0 ? raw_max : (a < 0 ? raw_min : 0);
  const bool negative = (a < 0) != (b < 0);
  const std::uint64_t n = magnitude(a);
  const std::uint64_t d = magnitude(b);
  const wide::U128 numerator{n >> 32, n << 32};                // |a| * 2^32
  if (numerator.hi >= d) return negative ? raw_min : raw_max;  // quotient >= 2^64
  const wide::DivResult qr = Ops::div(numerator, d);
  // Ties to even: compare twice the remainder with the divisor (2 * rem < 2^64 since rem < d).
  const std::uint64_t twice = qr.remainder << 1;
  const bool over_half = (qr.remainder >> 63) != 0 || twice > d;
  const bool up = over_half || (twice == d && (qr.quotient & 1U) != 0);
  if (up && qr.quotient == ~std::uint64_t{0}) return negative ? raw_min : raw_max;
  return signed_saturate(negative, qr.quotient + (up ? 1U : 0U));
}

}  // namespace detail

/// Q32.32 fixed-point number: 32 integer bits (including sign) and 32 fraction bits.
class Fixed {
 public:
  using raw_type = std::int64_t;
  static constexpr int fraction_bits = detail::fraction_bits;
  static constexpr raw_type one_raw = raw_type{1} << fraction_bits;

  /// Zero.
  constexpr Fixed() noexcept = default;

  /// Builds a Fixed from its raw two's-complement bits (value = raw / 2^32). No rounding, no check:
  /// use it for serialisation and for constants whose bits you derived, not for conversions.
  [[nodiscard]] static constexpr Fixed from_raw(raw_type raw) noexcept {
    Fixed f;
    f.raw_ = raw;
    return f;
  }

  /// The exact value of an integer. Every int32 is representable.
  [[nodiscard]] static constexpr Fixed from_int(std::int32_t value) noexcept {
    return from_raw(static_cast<raw_type>(static_cast<std::uint64_t>(static_cast<raw_type>(value))
                                          << fraction_bits));
  }

  /// Parses decimal text ("-12.5", "0.001", "3.14159265358979323846", "1e-3") exactly, rounded to
  /// nearest with ties to even. Junk, empty input and out-of-range values give an error value,
  /// never an exception. Defined in <detsim/fixed/decimal.hpp>.
  [[nodiscard]] static constexpr ParseResult parse(std::string_view text) noexcept;

  /// The raw bits (value * 2^32).
  [[nodiscard]] constexpr raw_type raw() const noexcept { return raw_; }

  /// Nearest integer, ties to even (the one rounding rule). Every Fixed is in int32 range after
  /// rounding except values >= 2^31 - 0.5, which saturate to INT32_MAX.
  [[nodiscard]] constexpr std::int32_t to_int() const noexcept;

  /// Display only: the nearest binary floating-point value. Never feed it back into simulation
  /// state (docs/DETERMINISM.md, rule 1).
  // clang-format off
  [[nodiscard]] double to_double() const noexcept { return static_cast<double>(raw_) * 0x1p-32; }
  // clang-format on

  [[nodiscard]] static constexpr Fixed max() noexcept {
    return from_raw(std::numeric_limits<raw_type>::max());
  }
  /// The most negative value, -2^31.
  [[nodiscard]] static constexpr Fixed min() noexcept {
    return from_raw(std::numeric_limits<raw_type>::min());
  }
  /// One ulp, 2^-32: the smallest positive value.
  [[nodiscard]] static constexpr Fixed epsilon() noexcept { return from_raw(1); }
  [[nodiscard]] static constexpr Fixed zero() noexcept { return from_raw(0); }
  [[nodiscard]] static constexpr Fixed one() noexcept { return from_raw(one_raw); }
  [[nodiscard]] static constexpr Fixed half() noexcept { return from_raw(one_raw / 2); }

  // Mathematical constants, each the correctly rounded Q32.32 value (tests derive them with MPFR).
  [[nodiscard]] static constexpr Fixed pi() noexcept { return from_raw(0x3243F6A89); }
  [[nodiscard]] static constexpr Fixed half_pi() noexcept { return from_raw(0x1921FB544); }
  [[nodiscard]] static constexpr Fixed two_pi() noexcept { return from_raw(0x6487ED511); }
  [[nodiscard]] static constexpr Fixed e() noexcept { return from_raw(0x2B7E15163); }
  [[nodiscard]] static constexpr Fixed ln2() noexcept { return from_raw(0xB17217F8); }
  [[nodiscard]] static constexpr Fixed sqrt2() noexcept { return from_raw(0x16A09E668); }

  friend constexpr bool operator==(Fixed, Fixed) noexcept = default;
  friend constexpr std::strong_ordering operator<=>(Fixed a, Fixed b) noexcept {
    return a.raw_ <=> b.raw_;
  }

  /// Saturating negation: -min() == max().
  friend constexpr Fixed operator-(Fixed a) noexcept {
    return a.raw_ == std::numeric_limits<raw_type>::min()
               ? max()
               : from_raw(static_cast<raw_type>(0U - static_cast<std::uint64_t>(a.raw_)));
  }
  friend constexpr Fixed operator+(Fixed a) noexcept { return a; }

  /// Saturating addition.
  friend constexpr Fixed operator+(Fixed a, Fixed b) noexcept {
    const auto sum = static_cast<raw_type>(static_cast<std::uint64_t>(a.raw_) +
                                           static_cast<std::uint64_t>(b.raw_));
    // Overflow iff both operands have the same sign and the sum's sign differs.
    if (((a.raw_ ^ sum) & (b.raw_ ^ sum)) < 0) return a.raw_ < 0 ? min() : max();
    return from_raw(sum);
  }

  /// Saturating subtraction.
  friend constexpr Fixed operator-(Fixed a, Fixed b) noexcept {
    const auto diff = static_cast<raw_type>(static_cast<std::uint64_t>(a.raw_) -
                                            static_cast<std::uint64_t>(b.raw_));
    // Overflow iff the operands have different signs and the result's sign differs from a's.
    if (((a.raw_ ^ b.raw_) & (a.raw_ ^ diff)) < 0) return a.raw_ < 0 ? min() : max();
    return from_raw(diff);
  }

  /// Product rounded to nearest (ties to even), saturated.
  friend constexpr Fixed operator*(Fixed a, Fixed b) noexcept {
    return from_raw(detail::fixed_mul<wide::Default>(a.raw_, b.raw_));
  }

  /// Quotient rounded to nearest (ties to even), saturated; x / 0 saturates with x's sign, 0 / 0 =
  /// 0.
  friend constexpr Fixed operator/(Fixed a, Fixed b) noexcept {
    return from_raw(detail::fixed_div<wide::Default>(a.raw_, b.raw_));
  }

  /// x * 2^n, saturating. A negative n shifts right.
  friend constexpr Fixed operator<<(Fixed a, int n) noexcept;
  /// x / 2^n, rounded to nearest (ties to even). A negative n shifts left.
  friend constexpr Fixed operator>>(Fixed a, int n) noexcept;

  constexpr Fixed& operator+=(Fixed b) noexcept { return *this = *this + b; }
  constexpr Fixed& operator-=(Fixed b) noexcept { return *this = *this - b; }
  constexpr Fixed& operator*=(Fixed b) noexcept { return *this = *this * b; }
  constexpr Fixed& operator/=(Fixed b) noexcept { return *this = *this / b; }
  constexpr Fixed& operator<<=(int n) noexcept { return *this = *this << n; }
  constexpr Fixed& operator>>=(int n) noexcept { return *this = *this >> n; }

 private:
  raw_type raw_ = 0;
};

static_assert(sizeof(Fixed) == 8, "Fixed is exactly its 64-bit raw value");

constexpr std::int32_t Fixed::to_int() const noexcept {
  const std::uint64_t mag = detail::magnitude(raw_);
  const std::uint64_t rounded = detail::round_shift_right(wide::U128{0, mag}, fraction_bits);
  if (raw_ < 0)
    return rounded >= (std::uint64_t{1} << 31) ? std::numeric_limits<std::int32_t>::min()
                                               : -static_cast<std::int32_t>(rounded);
  return rounded > 0x7FFFFFFFU ? std::numeric_limits<std::int32_t>::max()
                               : static_cast<std::int32_t>(rounded);
}

constexpr Fixed operator<<(Fixed a, int n) noexcept {
  if (n < 0) return a >> (n == std::numeric_limits<int>::min() ? 64 : -n);
  if (a.raw_ == 0 || n == 0) return a;
  if (n >= 63) return a.raw_ < 0 ? Fixed::min() : Fixed::max();
  const std::int64_t limit = detail::raw_max >> n;
  if (a.raw_ > limit) return Fixed::max();
  if (a.raw_ < -limit - 1) return Fixed::min();
  return Fixed::from_raw(static_cast<std::int64_t>(static_cast<std::uint64_t>(a.raw_) << n));
}

constexpr Fixed operator>>(Fixed a, int n) noexcept {
  if (n < 0) return a << (n == std::numeric_limits<int>::min() ? 64 : -n);
  if (n == 0) return a;
  if (n > 64) return Fixed{};  // |value| < 2^-1 after the shift: rounds to zero
  const std::uint64_t rounded =
      detail::round_shift_right(wide::U128{0, detail::magnitude(a.raw_)}, static_cast<unsigned>(n));
  return Fixed::from_raw(detail::signed_saturate(a.raw_ < 0, rounded));
}

/// Products of Fixed and int32 are exact before saturation; these spare the reader a from_int.
constexpr Fixed operator*(Fixed a, std::int32_t b) noexcept {
  return a * Fixed::from_int(b);
}
constexpr Fixed operator*(std::int32_t a, Fixed b) noexcept {
  return Fixed::from_int(a) * b;
}

}  // namespace detsim

#include <detsim/fixed/decimal.hpp>  // Fixed::parse, to_string, the _fx literal

// Exact conversions between decimal text and Fixed: Fixed::parse, the _fx literal and to_string.
//
// No floating point anywhere on the way: the digits are gathered into integers by their decimal
// weight and the exact decimal value is rounded once, to nearest with ties to even, whatever the
// length of the text or the size of its exponent. Nothing allocates; the work is linear in the
// length of the text and independent of the exponent's value.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <detsim/fixed/fixed.hpp>

namespace detsim {

/// Why Fixed::parse rejected its input. Grammar: [+-]? digits with at most one '.' (at least one
/// digit in all), then optionally [eE][+-]?digits. No whitespace, nothing else.
enum class ParseError : std::uint8_t {
  none = 0,
  empty,                    ///< the text has no characters
  no_digits,                ///< no digit before the end or the exponent: "-", "+", ".", "-.e5"
  missing_exponent_digits,  ///< an exponent marker without digits: "1e", "1e+"
  invalid_character,        ///< a character outside the grammar or in the wrong place
  out_of_range,             ///< the rounded value is outside [Fixed::min(), Fixed::max()]
};

/// A short English description of `error`, for messages to the user ("" never; "unknown parse
/// error" for a value outside the enumeration).
[[nodiscard]] constexpr const char* describe(ParseError error) noexcept {
  switch (error) {
    case ParseError::none:
      return "no error";
    case ParseError::empty:
      return "empty text";
    case ParseError::no_digits:
      return "no digits in the number";
    case ParseError::missing_exponent_digits:
      return "exponent marker without exponent digits";
    case ParseError::invalid_character:
      return "invalid character in the number";
    case ParseError::out_of_range:
      return "value outside the Fixed range [-2147483648, 2147483647.9999999998]";
  }
  return "unknown parse error";
}

/// Result of Fixed::parse: a value, or the reason there is none and where it was found.
struct ParseResult {
  /// The parsed value; zero when `error` is set.
  Fixed value{};
  ParseError error = ParseError::none;
  /// Index of the first offending character: the offending character for invalid_character, the
  /// index where a digit was expected (possibly the text's size) for no_digits and
  /// missing_exponent_digits, 0 for empty and out_of_range (the whole text), 0 on success.
  std::size_t position = 0;

  [[nodiscard]] constexpr bool ok() const noexcept { return error == ParseError::none; }
  constexpr explicit operator bool() const noexcept { return ok(); }
};

/// The shortest decimal text that Fixed::parse reads back as exactly `x`; among equally short
/// texts, the one nearest to the exact value of `x` (an exact tie keeps the even last digit).
/// Plain notation, no exponent, no trailing zeros: "-12.5", "0", "3", "0.0000000002". At most 10
/// fraction digits and 22 characters ("-2147483647.9999999998").
[[nodiscard]] std::string to_string(Fixed x);

namespace detail::decimal {

constexpr std::uint64_t power(std::uint64_t base, int exponent) noexcept {
  std::uint64_t p = 1;
  for (int i = 0; i < exponent; ++i)
    p *= base;
  return p;
}

inline constexpr std::uint64_t pow10[20] = {
    power(10, 0),  power(10, 1),  power(10, 2),  power(10, 3),  power(10, 4),
    power(10, 5),  power(10, 6),  power(10, 7),  power(10, 8),  power(10, 9),
    power(10, 10), power(10, 11), power(10, 12), power(10, 13), power(10, 14),
    power(10, 15), power(10, 16), power(10, 17), power(10, 18), power(10, 19)};

// Exactness argument for the fraction. Let f in [0, 1) be the fraction part of the value, N the
// integer formed by its first K = 33 decimal places and t = f - N / 10^33 the tail, 0 <= t <
// 10^-33. Then f * 2^33 = N / 5^33 + t * 2^33 = b + r / 5^33 + t * 2^33 with b = floor(N / 5^33)
// and r = N mod 5^33 < 5^33. Since t * 2^33 < 2^33 / 10^33 = 1 / 5^33, the sum r / 5^33 + t * 2^33
// is < (r + 1) / 5^33 <= 1: the tail never carries into b. So b gives the 32 result bits and the
// half bit exactly, and the rest is nonzero iff r != 0 or some digit after place 33 is nonzero
// (the sticky bit). K = 33 is the least number of places for which this bound holds.
inline constexpr int fraction_places = 33;
// The first 16 places go to `high`, the next 17 to `low`: N = high * 10^17 + low, each < 2^64.
inline constexpr int high_places = 16;
// N / 5^33 in two exact steps, floor(floor(N / 5^27) / 5^6): N < 10^33 < 2^110, so N's high word
// is below 5^27 (about 2^62.7) as the 128/64 division requires, and the remainder N mod 5^33 =
// 5^27 * r2 + r1 is zero iff both step remainders r1, r2 are.
inline constexpr std::uint64_t five_27 = power(5, 27);
inline constexpr std::uint64_t five_6 = power(5, 6);
// Integer digits: a nonzero digit of weight 10^10 or more puts the value out of range whatever
// the rounding (10^10 > 2^31 + 1).
inline constexpr int integer_places = 10;
// Digit counts and the exponent are clamped so that `index - point` below never overflows. The
// clamps change nothing for any text shorter than 10^18 - 50 characters: a nonzero digit whose
// place depends on the clamped part is then far outside the window of places -10 .. 33.
inline constexpr std::uint64_t exponent_clamp = pow10[18];
// (A count, not a size: a 32-bit size_t never reaches it, so the comparison is made in 64 bits.)
inline constexpr std::uint64_t count_clamp = std::uint64_t{1} << 61;

constexpr bool is_digit(char c) noexcept {
  return c >= '0' && c <= '9';
}

constexpr std::int64_t clamped_count(std::size_t n) noexcept {
  const std::uint64_t count = n;
  return static_cast<std::int64_t>(count < count_clamp ? count : count_clamp);
}

constexpr ParseResult failure(ParseError error, std::size_t position) noexcept {
  return ParseResult{Fixed{}, error, position};
}

/// Nonzero digits gathered by place: place p < 0 has weight 10^(-p-1), place p >= 0 (the
/// (p+1)-th decimal place) weight 10^-(p+1).
struct Digits {
  std::uint64_t integer = 0;  ///< places -10 .. -1, < 10^10
  std::uint64_t high = 0;     ///< places 0 .. 15 as an integer, < 10^16
  std::uint64_t low = 0;      ///< places 16 .. 32 as an integer, < 10^17
  bool sticky = false;        ///< a nonzero digit at place 33 or later
  bool too_large = false;     ///< a nonzero digit at place -11 or earlier

  constexpr void add(std::uint64_t digit, std::int64_t place) noexcept {
    if (place < -integer_places) {
      too_large = true;
    } else if (place < 0) {
      integer += digit * pow10[-place - 1];
    } else if (place < high_places) {
      high += digit * pow10[high_places - 1 - place];
    } else if (place < fraction_places) {
      low += digit * pow10[fraction_places - 1 - place];
    } else {
      sticky = true;
    }
  }
};

/// Pass 1's findings: where the mantissa is and where its decimal point stands once the exponent
/// has moved it.
struct Layout {
  ParseError error = ParseError::none;
  std::size_t error_position = 0;
  bool negative = false;
  std::size_t mantissa_begin = 0;
  std::size_t mantissa_end = 0;
  std::int64_t point = 0;  ///< digits before the point, after the exponent (clamped)
};

constexpr Layout layout_error(ParseError error, std::size_t position) noexcept {
  Layout layout;
  layout.error = error;
  layout.error_position = position;
  return layout;
}

/// Pass 1: the grammar. `literal` accepts the digit separator '\'' (the compiler has already
/// checked where it stands).
constexpr Layout scan(std::string_view text, bool literal) noexcept {
  const std::size_t n = text.size();
  if (n == 0) return layout_error(ParseError::empty, 0);
  Layout layout;
  std::size_t i = 0;
  layout.negative = text[0] == '-';
  if (text[0] == '-' || text[0] == '+') i = 1;
  layout.mantissa_begin = i;
  std::size_t digits = 0;
  std::size_t integer_digits = 0;
  bool seen_point = false;
  for (; i < n; ++i) {
    const char c = text[i];
    if (is_digit(c)) {
      ++digits;
      if (!seen_point) ++integer_digits;
    } else if (c == '.' && !seen_point) {
      seen_point = true;
    } else if (!(literal && c == '\'')) {
      break;
    }
  }
  layout.mantissa_end = i;
  const bool has_exponent = i < n && (text[i] == 'e' || text[i] == 'E');
  if (digits == 0) {
    return layout_error(
        i < n && !has_exponent ? ParseError::invalid_character : ParseError::no_digits, i);
  }
  std::uint64_t exponent = 0;
  bool exponent_negative = false;
  if (has_exponent) {
    ++i;
    if (i < n && (text[i] == '-' || text[i] == '+')) {
      exponent_negative = text[i] == '-';
      ++i;
    }
    std::size_t exponent_digits = 0;
    for (; i < n; ++i) {
      const char c = text[i];
      if (is_digit(c)) {
        ++exponent_digits;
        if (exponent < exponent_clamp) {
          exponent = exponent * 10 + static_cast<std::uint64_t>(c - '0');
        }
      } else if (!(literal && c == '\'')) {
        break;
      }
    }
    if (exponent_digits == 0) {
      return layout_error(
          i < n ? ParseError::invalid_character : ParseError::missing_exponent_digits, i);
    }
    if (exponent > exponent_clamp) exponent = exponent_clamp;
  }
  if (i < n) return layout_error(ParseError::invalid_character, i);
  const auto shift = static_cast<std::int64_t>(exponent);
  layout.point = clamped_count(integer_digits) + (exponent_negative ? -shift : shift);
  return layout;
}

/// Pass 2: the k-th mantissa digit (from 0) stands at place k - point.
constexpr Digits gather(std::string_view text, const Layout& layout) noexcept {
  Digits d;
  std::size_t index = 0;
  for (std::size_t j = layout.mantissa_begin; j < layout.mantissa_end; ++j) {
    const char c = text[j];
    if (!is_digit(c)) continue;
    const std::int64_t place = clamped_count(index) - layout.point;
    ++index;
    if (c == '0') continue;
    d.add(static_cast<std::uint64_t>(c - '0'), place);
    if (d.too_large || d.sticky) break;  // later digits can change neither outcome
  }
  return d;
}

/// The digits' exact value rounded to nearest, ties to even, then checked against the range.
constexpr ParseResult round_to_fixed(const Digits& d, bool negative) noexcept {
  if (d.too_large || d.integer > (std::uint64_t{1} << 31)) {
    return failure(ParseError::out_of_range, 0);
  }
  // b = floor(f * 2^33): the 32 fraction bits and the half bit (see the argument above).
  const wide::U128 places =
      wide::add(wide::Default::mul(d.high, pow10[fraction_places - high_places]), {0, d.low});
  const wide::DivResult step1 = wide::Default::div(places, five_27);
  const std::uint64_t b = step1.quotient / five_6;
  const bool sticky = d.sticky || step1.remainder != 0 || step1.quotient % five_6 != 0;
  const std::uint64_t truncated = b >> 1;
  // integer * 2^32 is even, so the parity that breaks a tie is truncated's.
  const bool up = (b & 1U) != 0 && (sticky || (truncated & 1U) != 0);
  // <= 2^63 + 2^32: no wrap.
  const std::uint64_t magnitude = (d.integer << fraction_bits) + truncated + (up ? 1U : 0U);
  const std::uint64_t limit = (std::uint64_t{1} << 63) - (negative ? 0U : 1U);
  if (magnitude > limit) return failure(ParseError::out_of_range, 0);
  return ParseResult{Fixed::from_raw(signed_saturate(negative, magnitude)), ParseError::none, 0};
}

/// The one parser behind Fixed::parse and the _fx literal. Syntax errors win over out_of_range.
constexpr ParseResult parse_decimal(std::string_view text, bool literal) noexcept {
  const Layout layout = scan(text, literal);
  if (layout.error != ParseError::none) return failure(layout.error, layout.error_position);
  return round_to_fixed(gather(text, layout), layout.negative);
}

/// In a literal, an integer with a leading 0 would be octal to C++ readers ("010" is 8): refuse.
constexpr bool looks_octal(std::string_view text) noexcept {
  if (text.size() < 2 || text[0] != '0') return false;
  for (const char c : text) {
    if (!is_digit(c) && c != '\'') return false;  // '.', an exponent, 'x', 'b': not an integer
  }
  return true;
}

template <char... Cs>
inline constexpr char literal_text[] = {Cs...};

}  // namespace detail::decimal

constexpr ParseResult Fixed::parse(std::string_view text) noexcept {
  return detail::decimal::parse_decimal(text, false);
}

inline namespace literals {

/// A Fixed from a decimal literal, read from its exact source digits and rounded like
/// Fixed::parse: `1.25_fx`, `3_fx`, `1e-3_fx`, `1'000.5_fx`. `-0.5_fx` is the negation of `0.5_fx`
/// (the same value, since ties to even is symmetric). A literal that is out of range, not decimal
/// (`0x10_fx`) or octal-looking (`010_fx`) does not compile.
template <char... Cs>
consteval Fixed operator""_fx() {
  constexpr std::string_view text(detail::decimal::literal_text<Cs...>, sizeof...(Cs));
  constexpr ParseResult result = detail::decimal::parse_decimal(text, true);
  static_assert(result.error != ParseError::out_of_range,
                "_fx literal out of range: Fixed holds [-2147483648, 2147483647.9999999998]");
  static_assert(result.error == ParseError::none || result.error == ParseError::out_of_range,
                "_fx literal must be a decimal number such as 1.25_fx or 1e-3_fx");
  static_assert(!detail::decimal::looks_octal(text),
                "_fx literal with a leading 0 reads as octal in C++: drop the leading zeros");
  return result.value;
}

}  // namespace literals

}  // namespace detsim

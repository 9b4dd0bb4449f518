// Decimal text <-> Fixed: Fixed::parse, the _fx literal and to_string.
//
// Expected values are derived independently of the code under test: by hand (the derivation is in
// the comment), from the exact decimal expansion of a dyadic value (every Fixed, and every tie
// (2k + 1) / 2^33, has a finite one, computed here with 128-bit integers), or by checking the
// defining inequality exactly (shortest, nearest) with 128-bit integers.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/fixed.hpp>

#include "support/print.hpp"
#include "support/scale.hpp"

namespace detsim {
namespace {

__extension__ using u128 = unsigned __int128;
__extension__ using i128 = __int128;

constexpr std::int64_t kOne = Fixed::one_raw;
constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMin = std::numeric_limits<std::int64_t>::min();

Fixed raw(std::int64_t r) {
  return Fixed::from_raw(r);
}

std::uint64_t magnitude(std::int64_t r) {
  return r < 0 ? 0U - static_cast<std::uint64_t>(r) : static_cast<std::uint64_t>(r);
}

// The exact decimal expansion of +-(integer + fraction / 2^bits), fraction < 2^bits, bits <= 33:
// fraction / 2^bits = fraction * 5^bits / 10^bits, and fraction * 5^bits < 2^33 * 5^33 < 2^110.
std::string exact_decimal(bool negative, std::uint64_t integer, std::uint64_t fraction, int bits) {
  u128 scaled = fraction;
  for (int i = 0; i < bits; ++i)
    scaled *= 5;
  std::string places(static_cast<std::size_t>(bits), '0');
  for (std::size_t i = places.size(); i-- > 0;) {
    places[i] = static_cast<char>('0' + static_cast<int>(scaled % 10));
    scaled /= 10;
  }
  while (!places.empty() && places.back() == '0')
    places.pop_back();
  std::string text = negative ? "-" : "";
  text += std::to_string(integer);
  if (!places.empty()) text += "." + places;
  return text;
}

// The exact decimal value of a Fixed.
std::string exact_decimal(Fixed x) {
  const std::uint64_t m = magnitude(x.raw());
  return exact_decimal(x.raw() < 0, m >> 32, m & 0xFFFFFFFFU, 32);
}

// The exact decimal value of the midpoint between raw values r and r + 1, (2r + 1) / 2^33, for
// r >= 0 (negate the text for the midpoint between -r and -r - 1).
std::string exact_midpoint(bool negative, std::uint64_t r) {
  const std::uint64_t twice = 2 * (r & 0xFFFFFFFFU) + 1;  // < 2^33
  return exact_decimal(negative, r >> 32, twice, 33);
}

// Decimal text of +-m / 10^places (m >= 0), without any rounding: the test's own formatter.
std::string format_scaled(bool negative, u128 m, int places) {
  std::string digits;
  do {
    digits.insert(digits.begin(), static_cast<char>('0' + static_cast<int>(m % 10)));
    m /= 10;
  } while (m != 0);
  while (digits.size() <= static_cast<std::size_t>(places))
    digits.insert(digits.begin(), '0');
  if (places > 0) digits.insert(digits.end() - places, '.');
  return (negative ? "-" : "") + digits;
}

::testing::AssertionResult parses_to(std::string_view text, std::int64_t expected) {
  const ParseResult r = Fixed::parse(text);
  if (!r.ok()) {
    return ::testing::AssertionFailure()
           << "'" << text.substr(0, 80) << "' (" << text.size() << " chars): " << describe(r.error)
           << " at " << r.position;
  }
  if (r.value.raw() != expected) {
    return ::testing::AssertionFailure()
           << "'" << text.substr(0, 80) << "' (" << text.size() << " chars) parsed to "
           << ::testing::PrintToString(r.value) << ", expected "
           << ::testing::PrintToString(raw(expected));
  }
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult fails_with(std::string_view text, ParseError error,
                                      std::size_t position) {
  const ParseResult r = Fixed::parse(text);
  if (r.error != error || r.position != position || r.value != Fixed{}) {
    return ::testing::AssertionFailure()
           << "'" << text.substr(0, 80) << "': got '" << describe(r.error) << "' at " << r.position
           << " value " << ::testing::PrintToString(r.value) << ", expected '" << describe(error)
           << "' at " << position;
  }
  return ::testing::AssertionSuccess();
}

// Operands over the whole range: uniform bits, random magnitudes (small values common), values
// next to integers and next to the extremes.
std::vector<std::int64_t> random_raws(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::int64_t> v;
  v.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t bits = rng();
    std::uint64_t mag = bits;
    switch (i % 4) {
      case 0:
        break;
      case 1: {
        const auto width = static_cast<unsigned>(rng() % 64);
        mag = width == 0 ? 0 : bits >> (64 - width);
        break;
      }
      case 2:  // an integer plus or minus a few ulps
        mag = (bits & ~std::uint64_t{0xFFFFFFFF}) + (rng() % 9) - 4;
        break;
      default:  // a small number of decimal places: k / 10^j
        mag = (bits % 1000000) * static_cast<std::uint64_t>(kOne) / 1000;
        break;
    }
    v.push_back(static_cast<std::int64_t>(mag));
  }
  return v;
}

std::vector<std::int64_t> edge_raws() {
  std::vector<std::int64_t> v = {0,        1,         -1,        2,        -2,       kOne,
                                 -kOne,    kMax,      kMax - 1,  kMin,     kMin + 1, kOne + 1,
                                 kOne - 1, -kOne + 1, -kOne - 1, kOne / 2, -kOne / 2};
  for (int s = 0; s < 63; ++s) {
    const std::int64_t p = std::int64_t{1} << s;
    for (const std::int64_t r : {p, -p, p + 1, p - 1, -p + 1, -p - 1})
      v.push_back(r);
  }
  return v;
}

// ---- parse: values derived by hand -----------------------------------------------------------

TEST(DecimalParse, KnownValues) {
  // value * 2^32, worked out by hand.
  EXPECT_TRUE(parses_to("0.5", std::int64_t{1} << 31));
  EXPECT_TRUE(parses_to("1.25", std::int64_t{5} << 30));
  EXPECT_TRUE(parses_to("-12.5", -(std::int64_t{25} << 31)));
  EXPECT_TRUE(parses_to("3", 3 * kOne));
  EXPECT_TRUE(parses_to("+3", 3 * kOne));
  EXPECT_TRUE(parses_to("0", 0));
  EXPECT_TRUE(parses_to("-0", 0));
  EXPECT_TRUE(parses_to("+0.000", 0));
  EXPECT_TRUE(parses_to(".5", kOne / 2));
  EXPECT_TRUE(parses_to("5.", 5 * kOne));
  EXPECT_TRUE(parses_to("00012.500", 25 * kOne / 2));
  EXPECT_TRUE(parses_to("0.0000152587890625", std::int64_t{1} << 16));  // 2^-16
  EXPECT_TRUE(parses_to("0.00000000023283064365386962890625", 1));      // 2^-32
  EXPECT_TRUE(parses_to("-0.00000000023283064365386962890625", -1));
  EXPECT_TRUE(parses_to("2147483647", std::int64_t{0x7FFFFFFF} * kOne));
  EXPECT_TRUE(parses_to("-2147483648", kMin));  // exactly representable
  // 0.1 * 2^32 = 429496729.6 -> 429496730; 0.001 * 2^32 = 4294967.296 -> 4294967.
  EXPECT_TRUE(parses_to("0.1", 429496730));
  EXPECT_TRUE(parses_to("-0.1", -429496730));
  EXPECT_TRUE(parses_to("0.001", 4294967));
  // 2^-32 = 2.33e-10: 1e-10 rounds to 0, 2e-10 to 1, 3.5e-10 (1.503 ulp) to 2.
  EXPECT_TRUE(parses_to("0.0000000001", 0));
  EXPECT_TRUE(parses_to("0.0000000002", 1));
  EXPECT_TRUE(parses_to("0.00000000035", 2));
  // Correctly rounded pi, as Fixed::pi() (derived with MPFR by the arithmetic tests).
  EXPECT_TRUE(parses_to("3.14159265358979323846264338327950288", Fixed::pi().raw()));
}

TEST(DecimalParse, IsConstexpr) {
  static_assert(Fixed::parse("1.25").value == Fixed::from_raw(std::int64_t{5} << 30));
  static_assert(Fixed::parse("-2147483648").value == Fixed::min());
  static_assert(Fixed::parse("1e-3").value == Fixed::from_raw(4294967));
  static_assert(Fixed::parse("2147483648").error == ParseError::out_of_range);
  static_assert(Fixed::parse("1.2.3").position == 3);
  static_assert(!Fixed::parse(""));
}

TEST(DecimalParse, EveryFixedParsesFromItsExactExpansion) {
  for (const std::int64_t r : edge_raws())
    EXPECT_TRUE(parses_to(exact_decimal(raw(r)), r));
  for (const std::int64_t r : random_raws(200000, 11)) {
    ASSERT_TRUE(parses_to(exact_decimal(raw(r)), r));
  }
}

// ---- parse: ties and long inputs -------------------------------------------------------------

TEST(DecimalParse, ExactTiesRoundToEven) {
  // 2^-33 = 1.16415321826934814453125e-10 sits between raw 0 and 1: goes to 0 (even).
  EXPECT_EQ(exact_midpoint(false, 0), "0.000000000116415321826934814453125");
  EXPECT_TRUE(parses_to("0.000000000116415321826934814453125", 0));
  EXPECT_TRUE(parses_to("-0.000000000116415321826934814453125", 0));
  EXPECT_TRUE(parses_to(exact_midpoint(false, 1), 2));  // 3 * 2^-33: between 1 and 2 -> 2
  EXPECT_TRUE(parses_to(exact_midpoint(false, 2), 2));  // 5 * 2^-33: between 2 and 3 -> 2
  EXPECT_TRUE(parses_to(exact_midpoint(true, 1), -2));
  EXPECT_TRUE(parses_to(exact_midpoint(true, 2), -2));
  // 1 + 2^-33: between kOne (even) and kOne + 1.
  EXPECT_TRUE(parses_to("1.000000000116415321826934814453125", kOne));

  std::mt19937_64 rng(7);
  for (int i = 0; i < 200000; ++i) {
    const std::uint64_t r = rng() >> (2 + rng() % 62);  // < 2^62: r + 1 is in range too
    const bool negative = (rng() & 1) != 0;
    const std::uint64_t even = (r & 1) == 0 ? r : r + 1;
    const std::int64_t expected =
        negative ? -static_cast<std::int64_t>(even) : static_cast<std::int64_t>(even);
    ASSERT_TRUE(parses_to(exact_midpoint(negative, r), expected));
  }
}

TEST(DecimalParse, ADistantStickyDigitBreaksATie) {
  // Each midpoint ends in the digit 5 at place 33 ((2r + 1) * 5^33 is an odd multiple of 5).
  // midpoint + 10^-1000: '0's up to place 999 then a 1. midpoint - 10^-1000: the final 5 becomes
  // a 4 followed by 9s up to place 1000.
  for (const std::uint64_t r :
       {std::uint64_t{0}, std::uint64_t{1}, std::uint64_t{2}, std::uint64_t{3},
        std::uint64_t{0x123456789}, std::uint64_t{kOne}, static_cast<std::uint64_t>(kMax) - 1}) {
    for (const bool negative : {false, true}) {
      const std::string tie = exact_midpoint(negative, r);
      const std::size_t places = tie.size() - tie.find('.') - 1;
      ASSERT_EQ(places, 33U) << tie;
      ASSERT_EQ(tie.back(), '5') << tie;
      const std::string above = tie + std::string(1000 - 33 - 1, '0') + "1";
      const std::string below = tie.substr(0, tie.size() - 1) + "4" + std::string(1000 - 33, '9');
      const auto sign = [&](std::uint64_t m) {
        return negative ? -static_cast<std::int64_t>(m) : static_cast<std::int64_t>(m);
      };
      const std::uint64_t even = (r & 1) == 0 ? r : r + 1;
      EXPECT_TRUE(parses_to(tie, sign(even)));
      EXPECT_TRUE(parses_to(above, sign(r + 1)));
      EXPECT_TRUE(parses_to(below, sign(r)));
    }
  }
}

TEST(DecimalParse, LongInputs) {
  const std::string zeros(1000, '0');
  EXPECT_TRUE(parses_to("0." + zeros + "1", 0));
  EXPECT_TRUE(parses_to(zeros + "1.5", 3 * kOne / 2));
  EXPECT_TRUE(parses_to("-" + zeros + "1.5" + zeros, -3 * kOne / 2));
  EXPECT_TRUE(parses_to("1" + zeros + "e-1000", kOne));
  EXPECT_TRUE(parses_to("0." + zeros + "5e+1001", 5 * kOne));
  EXPECT_TRUE(parses_to("1e-" + zeros + "1", 429496730));      // 1e-1 = 0.1
  EXPECT_TRUE(parses_to("1e+" + zeros + "5", 100000 * kOne));  // 1e5
  // 0.999... (1000 nines) is within 10^-1000 of 1: rounds to 1. With 9 nines it is 1 - 1e-9,
  // 4.29 ulps below 1: 2^32 - 4.29 -> 2^32 - 4.
  EXPECT_TRUE(parses_to("0." + std::string(1000, '9'), kOne));
  EXPECT_TRUE(parses_to("0.999999999", kOne - 4));
  // A million characters: linear time, no allocation.
  const std::string million(1000000, '0');
  EXPECT_TRUE(parses_to("0." + million + "1", 0));
  EXPECT_TRUE(parses_to(million + "2.5" + million, 5 * kOne / 2));
  EXPECT_TRUE(parses_to(million + "2." + million + "5", 2 * kOne));
  EXPECT_TRUE(parses_to("1" + million + "e-1000000", kOne));
}

// ---- parse: exponents ------------------------------------------------------------------------

TEST(DecimalParse, Exponents) {
  EXPECT_TRUE(parses_to("1e3", 1000 * kOne));
  EXPECT_TRUE(parses_to("1E3", 1000 * kOne));
  EXPECT_TRUE(parses_to("1e+2", 100 * kOne));
  EXPECT_TRUE(parses_to("1e-0", kOne));
  EXPECT_TRUE(parses_to("125e-2", std::int64_t{5} << 30));
  EXPECT_TRUE(parses_to("0.0125E+2", std::int64_t{5} << 30));
  EXPECT_TRUE(parses_to("1e-3", 4294967));
  EXPECT_TRUE(parses_to("1e9", 1000000000 * kOne));
  EXPECT_TRUE(parses_to("2.147483647e9", std::int64_t{0x7FFFFFFF} * kOne));
  EXPECT_TRUE(parses_to("-2.147483648e9", kMin));
  EXPECT_TRUE(fails_with("2.147483648e9", ParseError::out_of_range, 0));
  // 2^-32 = 2.3283064365386962890625e-10 exactly; 2^-33 = 1.16415321826934814453125e-10 (a tie).
  EXPECT_TRUE(parses_to("2.3283064365386962890625e-10", 1));
  EXPECT_TRUE(parses_to("1.16415321826934814453125e-10", 0));
  EXPECT_TRUE(parses_to("1.16415321826934814453126e-10", 1));
  EXPECT_TRUE(parses_to("1.16415321826934814453124e-10", 0));
  // Tiny and huge exponents: no overflow, no long loop.
  EXPECT_TRUE(parses_to("1e-999999999", 0));
  EXPECT_TRUE(parses_to("-1e-999999999", 0));
  EXPECT_TRUE(parses_to("9.99e-99999999999999999999999999", 0));
  EXPECT_TRUE(parses_to("0e999999999999999999999999", 0));
  EXPECT_TRUE(parses_to("0.000e+99999999999999999999999999", 0));
  EXPECT_TRUE(parses_to("-0e-99999999999999999999999999", 0));
  EXPECT_TRUE(fails_with("1e+999999999", ParseError::out_of_range, 0));
  EXPECT_TRUE(fails_with("-1e999999999", ParseError::out_of_range, 0));
  EXPECT_TRUE(fails_with("1e99999999999999999999999999", ParseError::out_of_range, 0));
  EXPECT_TRUE(fails_with("0.000001e99999999999999999999999999", ParseError::out_of_range, 0));
  EXPECT_TRUE(fails_with("1e2147483648", ParseError::out_of_range, 0));
  EXPECT_TRUE(parses_to("1e-2147483649", 0));
  EXPECT_TRUE(parses_to("1e-9223372036854775809", 0));
  EXPECT_TRUE(fails_with("1e18446744073709551617", ParseError::out_of_range, 0));
}

TEST(DecimalParse, MovingThePointIsTheSameAsTheExponent) {
  // d1...dn e E equals the same digits with the point moved E places, written out in full.
  std::mt19937_64 rng(3);
  for (int i = 0; i < 100000; ++i) {
    const auto n = 1 + static_cast<int>(rng() % 30);
    std::string digits;
    for (int j = 0; j < n; ++j)
      digits += static_cast<char>('0' + rng() % 10);
    const int point = static_cast<int>(rng() % 41) - 30;  // digits before the point, maybe < 0
    std::string moved;
    if (point <= 0) {
      moved = "0." + std::string(static_cast<std::size_t>(-point), '0') + digits;
    } else if (point >= n) {
      moved = digits + std::string(static_cast<std::size_t>(point - n), '0');
    } else {
      moved = digits.substr(0, static_cast<std::size_t>(point)) + "." +
              digits.substr(static_cast<std::size_t>(point));
    }
    const int split = static_cast<int>(rng() % static_cast<std::uint64_t>(n + 1));
    const std::string mantissa = digits.substr(0, static_cast<std::size_t>(split)) + "." +
                                 digits.substr(static_cast<std::size_t>(split));
    const std::string with_exponent = mantissa + "e" + std::to_string(point - split);
    const ParseResult a = Fixed::parse(moved);
    const ParseResult b = Fixed::parse(with_exponent);
    ASSERT_EQ(a.error, b.error) << moved << " vs " << with_exponent;
    ASSERT_EQ(a.value, b.value) << moved << " vs " << with_exponent;
  }
}

// ---- parse: the range --------------------------------------------------------------------------

TEST(DecimalParse, RangeBoundaries) {
  // max = 2^31 - 2^-32 (odd raw). Its upper midpoint max + 2^-33 ties to 2^31 (even): out of range.
  const std::string max_text = exact_decimal(Fixed::max());
  EXPECT_EQ(max_text, "2147483647.99999999976716935634613037109375");
  EXPECT_TRUE(parses_to(max_text, kMax));
  EXPECT_TRUE(parses_to("2147483647.9999999998", kMax));
  const std::string above_max = exact_midpoint(false, static_cast<std::uint64_t>(kMax));
  EXPECT_TRUE(fails_with(above_max, ParseError::out_of_range, 0));
  EXPECT_TRUE(parses_to(above_max.substr(0, above_max.size() - 1) + "4999", kMax));
  EXPECT_TRUE(fails_with("2147483648", ParseError::out_of_range, 0));
  EXPECT_TRUE(fails_with("2147483647.9999999999", ParseError::out_of_range, 0));
  // min = -2^31 (even raw). Its lower midpoint -2^31 - 2^-33 ties to min: in range.
  const std::string below_min = exact_midpoint(true, std::uint64_t{1} << 63);
  EXPECT_EQ(below_min, "-2147483648.000000000116415321826934814453125");
  EXPECT_TRUE(parses_to(below_min, kMin));
  EXPECT_TRUE(fails_with(below_min + "0001", ParseError::out_of_range, 0));
  EXPECT_TRUE(parses_to("-2147483648.0000000001", kMin));
  EXPECT_TRUE(fails_with("-2147483648.0000000002", ParseError::out_of_range, 0));
  EXPECT_TRUE(fails_with("-2147483649", ParseError::out_of_range, 0));
  EXPECT_TRUE(fails_with("99999999999", ParseError::out_of_range, 0));
  EXPECT_TRUE(fails_with("10000000000.5", ParseError::out_of_range, 0));
  EXPECT_TRUE(fails_with("4294967296", ParseError::out_of_range, 0));
}

TEST(DecimalParse, SignIsSymmetric) {
  for (const std::int64_t r : random_raws(100000, 5)) {
    if (r == kMin) continue;
    const std::string text = exact_decimal(raw(r < 0 ? -r : r));
    const std::string longer = text + (text.find('.') == std::string::npos ? ".3" : "3");
    const ParseResult plus = Fixed::parse(longer);
    const ParseResult minus = Fixed::parse("-" + longer);
    ASSERT_EQ(minus.value, -plus.value) << longer;
  }
}

// ---- parse: errors -----------------------------------------------------------------------------

TEST(DecimalParse, ErrorsAndTheirPositions) {
  EXPECT_TRUE(fails_with("", ParseError::empty, 0));
  EXPECT_TRUE(fails_with("-", ParseError::no_digits, 1));
  EXPECT_TRUE(fails_with("+", ParseError::no_digits, 1));
  EXPECT_TRUE(fails_with(".", ParseError::no_digits, 1));
  EXPECT_TRUE(fails_with("-.", ParseError::no_digits, 2));
  EXPECT_TRUE(fails_with("e5", ParseError::no_digits, 0));
  EXPECT_TRUE(fails_with("-e5", ParseError::no_digits, 1));
  EXPECT_TRUE(fails_with(".e1", ParseError::no_digits, 1));
  EXPECT_TRUE(fails_with("1e", ParseError::missing_exponent_digits, 2));
  EXPECT_TRUE(fails_with("1e+", ParseError::missing_exponent_digits, 3));
  EXPECT_TRUE(fails_with("1.5E-", ParseError::missing_exponent_digits, 5));
  EXPECT_TRUE(fails_with("x", ParseError::invalid_character, 0));
  EXPECT_TRUE(fails_with(" 1", ParseError::invalid_character, 0));
  EXPECT_TRUE(fails_with("1 ", ParseError::invalid_character, 1));
  EXPECT_TRUE(fails_with("1.2.3", ParseError::invalid_character, 3));
  EXPECT_TRUE(fails_with("1e5.3", ParseError::invalid_character, 3));
  EXPECT_TRUE(fails_with("1e+x", ParseError::invalid_character, 3));
  EXPECT_TRUE(fails_with("1ex", ParseError::invalid_character, 2));
  EXPECT_TRUE(fails_with("1e5e5", ParseError::invalid_character, 3));
  EXPECT_TRUE(fails_with("--1", ParseError::invalid_character, 1));
  EXPECT_TRUE(fails_with("+-1", ParseError::invalid_character, 1));
  EXPECT_TRUE(fails_with("-.x", ParseError::invalid_character, 2));
  EXPECT_TRUE(fails_with("1-", ParseError::invalid_character, 1));
  EXPECT_TRUE(fails_with("0x10", ParseError::invalid_character, 1));
  EXPECT_TRUE(fails_with("1'000", ParseError::invalid_character, 1));  // separators: literals only
  EXPECT_TRUE(fails_with("1,5", ParseError::invalid_character, 1));
  EXPECT_TRUE(fails_with("inf", ParseError::invalid_character, 0));
  EXPECT_TRUE(fails_with("nan", ParseError::invalid_character, 0));
  EXPECT_TRUE(fails_with("1.5f", ParseError::invalid_character, 3));
  EXPECT_TRUE(fails_with("\xD9\xA1", ParseError::invalid_character, 0));  // U+0661, a digit
  EXPECT_TRUE(fails_with(std::string_view("1\0", 2), ParseError::invalid_character, 1));
  // Syntax is checked before range: the bad character wins.
  EXPECT_TRUE(fails_with("1e999999999x", ParseError::invalid_character, 11));
  // A long valid prefix, then junk.
  EXPECT_TRUE(fails_with(std::string(5000, '7') + "?", ParseError::invalid_character, 5000));
}

TEST(DecimalParse, EveryErrorHasItsOwnDescription) {
  const ParseError all[] = {ParseError::none,
                            ParseError::empty,
                            ParseError::no_digits,
                            ParseError::missing_exponent_digits,
                            ParseError::invalid_character,
                            ParseError::out_of_range};
  for (const ParseError a : all) {
    EXPECT_GT(std::string(describe(a)).size(), 5U);
    for (const ParseError b : all) {
      if (a != b) {
        EXPECT_NE(std::string(describe(a)), std::string(describe(b)));
      }
    }
  }
  EXPECT_TRUE(Fixed::parse("1").ok());
  EXPECT_FALSE(static_cast<bool>(Fixed::parse("1x")));
}

// ---- the _fx literal -------------------------------------------------------------------------

TEST(DecimalLiteral, EqualsParseOfTheSameText) {
  // Inside namespace detsim the literal needs no using-directive.
  static_assert(1.25_fx == Fixed::parse("1.25").value);
  static_assert(1.25_fx == Fixed::from_raw(std::int64_t{5} << 30));
  static_assert(3_fx == Fixed::from_int(3));
  static_assert(0_fx == Fixed::zero());
  static_assert(0.5_fx == Fixed::half());
  static_assert(1e-3_fx == Fixed::parse("1e-3").value);
  static_assert(1E3_fx == Fixed::from_int(1000));
  static_assert(3.14159265358979323846_fx == Fixed::parse("3.14159265358979323846").value);
  static_assert(3.14159265358979323846_fx == Fixed::pi());
  static_assert(1'000.5_fx == Fixed::parse("1000.5").value);
  static_assert(1'000'000_fx == Fixed::from_int(1000000));
  static_assert(1.000'001_fx == Fixed::parse("1.000001").value);
  static_assert(1e0'1_fx == 10_fx);
  static_assert(-0.001_fx == Fixed::parse("-0.001").value);
  static_assert(-0.1_fx == Fixed::from_raw(-429496730));
  static_assert(2147483647.9999999998_fx == Fixed::max());
  static_assert(-2147483647.9999999998_fx == -Fixed::max());
  static_assert(0.000000000116415321826934814453125_fx == Fixed::zero());  // a tie, to even
  static_assert(0.000000000116415321826934814453126_fx == Fixed::epsilon());
  static_assert(1e-999999999_fx == Fixed::zero());
  static_assert(.5_fx == Fixed::half());
  static_assert(5._fx == Fixed::from_int(5));
  static_assert(0.0_fx == Fixed::zero());
  // The checks behind the literal's static_asserts.
  static_assert(detail::decimal::parse_decimal("1'000", true).value == Fixed::from_int(1000));
  static_assert(detail::decimal::parse_decimal("0x10", true).error ==
                ParseError::invalid_character);
  static_assert(detail::decimal::parse_decimal("1e10", true).error == ParseError::out_of_range);
  static_assert(detail::decimal::looks_octal("010"));
  static_assert(detail::decimal::looks_octal("0'7"));
  static_assert(!detail::decimal::looks_octal("0"));
  static_assert(!detail::decimal::looks_octal("0.5"));
  static_assert(!detail::decimal::looks_octal("0e5"));
  static_assert(!detail::decimal::looks_octal("10"));
  EXPECT_EQ(1.25_fx, Fixed::from_raw(std::int64_t{5} << 30));
}

}  // namespace
}  // namespace detsim

namespace user_code {

using namespace detsim::literals;

static_assert(2.5_fx == detsim::Fixed::parse("2.5").value);
static_assert(-12.5_fx == detsim::Fixed::from_raw(-(std::int64_t{25} << 31)));

TEST(DecimalLiteral, WorksThroughTheUsingDirective) {
  EXPECT_EQ(0.75_fx, detsim::Fixed::from_raw(std::int64_t{3} << 30));
}

}  // namespace user_code

namespace detsim {
namespace {

// ---- to_string -------------------------------------------------------------------------------

TEST(DecimalToString, KnownValues) {
  EXPECT_EQ(to_string(Fixed::zero()), "0");
  EXPECT_EQ(to_string(Fixed::from_int(3)), "3");
  EXPECT_EQ(to_string(Fixed::from_int(-7)), "-7");
  EXPECT_EQ(to_string(Fixed::half()), "0.5");
  EXPECT_EQ(to_string(raw(-(std::int64_t{25} << 31))), "-12.5");
  EXPECT_EQ(to_string(raw(std::int64_t{5} << 30)), "1.25");
  EXPECT_EQ(to_string(Fixed::min()), "-2147483648");
  EXPECT_EQ(to_string(Fixed::from_int(2147483647)), "2147483647");
  // One ulp, 2.328e-10: 0.0000000002 is 0.33e-10 away (inside the half-ulp 1.164e-10); no
  // 9-place decimal is (0 is 2.33e-10 away).
  EXPECT_EQ(to_string(Fixed::epsilon()), "0.0000000002");
  EXPECT_EQ(to_string(-Fixed::epsilon()), "-0.0000000002");
  // Two ulps, 4.657e-10: 0.0000000005 is 0.34e-10 away.
  EXPECT_EQ(to_string(raw(2)), "0.0000000005");
  // max = 2147483648 - 2.328e-10: 2147483647.9999999998 is 0.33e-10 below it; 9 places give
  // ...999999999 (2.33e-10 - 1e-9 away) or 2147483648: both outside.
  EXPECT_EQ(to_string(Fixed::max()), "2147483647.9999999998");
  // 2^-16 = 0.0000152587890625: with 9 places, 0.000015259 is 2.109e-10 above and 0.000015258
  // 7.89e-10 below, both beyond the half-ulp 1.164e-10; 0.0000152588 is 1.09e-11 above.
  EXPECT_EQ(to_string(raw(std::int64_t{1} << 16)), "0.0000152588");
  // 0.1 and 0.001 parse to raw values that "0.1" and "0.001" read back as; nothing shorter does.
  EXPECT_EQ(to_string(raw(429496730)), "0.1");
  EXPECT_EQ(to_string(raw(-429496730)), "-0.1");
  EXPECT_EQ(to_string(raw(4294967)), "0.001");
}

// Round trip and format: parse(to_string(x)) == x; "-"? digits ("." digits)?, at most ten places,
// no trailing zero in the fraction, no redundant leading zero.
::testing::AssertionResult round_trips(std::int64_t r) {
  const std::string text = to_string(raw(r));
  const ParseResult back = Fixed::parse(text);
  if (!back.ok() || back.value.raw() != r) {
    return ::testing::AssertionFailure()
           << ::testing::PrintToString(raw(r)) << " -> '" << text << "' -> " << describe(back.error)
           << " " << ::testing::PrintToString(back.value);
  }
  const bool negative = !text.empty() && text[0] == '-';
  const std::string body = negative ? text.substr(1) : text;
  const std::size_t point = body.find('.');
  const std::string integer = body.substr(0, point);
  const std::string fraction = point == std::string::npos ? "" : body.substr(point + 1);
  const bool integer_ok = !integer.empty() && (integer == "0" || integer[0] != '0') &&
                          integer.find_first_not_of("0123456789") == std::string::npos;
  const bool fraction_ok = point == std::string::npos ||
                           (!fraction.empty() && fraction.size() <= 10 && fraction.back() != '0' &&
                            fraction.find_first_not_of("0123456789") == std::string::npos);
  if (negative != (r < 0) || !integer_ok || !fraction_ok) {
    return ::testing::AssertionFailure() << "bad format '" << text << "' for raw " << r;
  }
  return ::testing::AssertionSuccess();
}

TEST(DecimalToString, RoundTripsEveryRawNearZero) {
  for (std::int64_t r = -(std::int64_t{1} << 20); r <= (std::int64_t{1} << 20); ++r) {
    ASSERT_TRUE(round_trips(r));
  }
}

TEST(DecimalToString, RoundTripsTenMillionRandomRaws) {
  for (const std::int64_t r : random_raws(test::scaled(10000000), 2024))
    ASSERT_TRUE(round_trips(r));
}

TEST(DecimalToString, RoundTripsTheEdges) {
  for (const std::int64_t r : edge_raws())
    EXPECT_TRUE(round_trips(r));
}

// Shortest and nearest, checked exactly. Let s = to_string(x) have k places, s = +-m / 10^k.
// Nearest: |m 2^32 - |raw| 10^k| <= 2^32 / 2 (ties: m even). Shortest: the two (k-1)-place
// decimals around x, floor(|raw| 10^(k-1) / 2^32) and one more, do not parse to x (parse is
// monotonic, so no other (k-1)-place decimal does either).
::testing::AssertionResult shortest_and_nearest(std::int64_t r) {
  const std::string text = to_string(raw(r));
  const bool negative = r < 0;
  const std::size_t point = text.find('.');
  const int places = point == std::string::npos ? 0 : static_cast<int>(text.size() - point - 1);
  u128 m = 0;
  for (const char c : text) {
    if (c >= '0' && c <= '9') m = m * 10 + static_cast<unsigned>(c - '0');
  }
  u128 scale = 1;
  for (int i = 0; i < places; ++i)
    scale *= 10;
  const u128 exact = static_cast<u128>(magnitude(r)) * scale;  // |x| 10^k 2^32
  const i128 distance = static_cast<i128>(m << 32) - static_cast<i128>(exact);
  const i128 twice = (distance < 0 ? -distance : distance) * 2;
  const i128 ulp = i128{1} << 32;
  if (twice > ulp || (twice == ulp && (m & 1) != 0)) {
    return ::testing::AssertionFailure()
           << "'" << text << "' is not the nearest " << places << "-place decimal to raw " << r;
  }
  if (places == 0) return ::testing::AssertionSuccess();
  const u128 below = static_cast<u128>(magnitude(r)) * (scale / 10) >> 32;
  for (const u128 c : {below, below + 1}) {
    const std::string shorter = format_scaled(negative, c, places - 1);
    const ParseResult p = Fixed::parse(shorter);
    if (p.ok() && p.value.raw() == r) {
      return ::testing::AssertionFailure()
             << "'" << shorter << "' is shorter than '" << text << "' and parses to raw " << r;
    }
  }
  return ::testing::AssertionSuccess();
}

TEST(DecimalToString, IsTheShortestAndTheNearest) {
  for (const std::int64_t r : edge_raws())
    EXPECT_TRUE(shortest_and_nearest(r));
  for (std::int64_t r = -5000; r <= 5000; ++r)
    ASSERT_TRUE(shortest_and_nearest(r));
  for (const std::int64_t r : random_raws(test::scaled(1000000), 99))
    ASSERT_TRUE(shortest_and_nearest(r));
}

TEST(DecimalToString, PrintToShowsDecimalAndRawBits) {
  EXPECT_EQ(::testing::PrintToString(raw(-(std::int64_t{25} << 31))),
            "-12.5 (raw 0xfffffff380000000)");
}

}  // namespace
}  // namespace detsim

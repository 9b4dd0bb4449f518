// Fixed::parse and to_string against MPFR.
//
// The reference for "the exact decimal value rounded to the 2^-32 grid, ties to even": MPFR reads
// the text once rounded down and once rounded up (mpfr_set_str), each bound is scaled by 2^32
// (exact) and rounded to an integer with ties to even (mpfr_rint, MPFR_RNDN). The exact value lies
// between the bounds, so when both round to the same integer that is the answer; otherwise the
// precision doubles. They always agree eventually: an exact tie is read exactly once the precision
// holds it, and any other value is a positive distance from every midpoint.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <mpfr.h>
#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/fixed.hpp>

#include "support/print.hpp"
#include "support/scale.hpp"

namespace detsim {
namespace {

class Real {
 public:
  explicit Real(mpfr_prec_t precision) { mpfr_init2(value_, precision); }
  ~Real() { mpfr_clear(value_); }
  Real(const Real&) = delete;
  Real& operator=(const Real&) = delete;
  mpfr_ptr get() { return value_; }

 private:
  mpfr_t value_;
};

class Integer {
 public:
  Integer() { mpz_init(value_); }
  ~Integer() { mpz_clear(value_); }
  Integer(const Integer&) = delete;
  Integer& operator=(const Integer&) = delete;
  mpz_ptr get() { return value_; }
  std::string decimal() {
    std::string s(mpz_sizeinbase(value_, 10) + 2, '\0');
    mpz_get_str(s.data(), 10, value_);
    s.resize(std::char_traits<char>::length(s.c_str()));
    return s;
  }

 private:
  mpz_t value_;
};

// digits with a '.' before index `at`. (Built by appending: GCC 12 at -O3 warns falsely about
// std::string::insert, -Wrestrict.)
std::string with_point(const std::string& digits, std::size_t at) {
  std::string text(digits, 0, at);
  text += '.';
  text.append(digits, at, std::string::npos);
  return text;
}

struct Reference {
  bool valid_syntax = false;
  bool in_range = false;
  std::int64_t raw = 0;
  mpfr_prec_t precision = 0;  // the precision at which the bounds agreed
};

// Rounds bound * 2^32 to an integer, ties to even, in place.
void round_to_grid(mpfr_ptr bound) {
  mpfr_mul_2si(bound, bound, Fixed::fraction_bits, MPFR_RNDN);  // exact
  mpfr_rint(bound, bound, MPFR_RNDN);
}

Reference mpfr_reference(const std::string& text) {
  Reference ref;
  for (mpfr_prec_t precision = 128; precision <= (mpfr_prec_t{1} << 22); precision *= 2) {
    Real low(precision);
    Real high(precision);
    if (mpfr_set_str(low.get(), text.c_str(), 10, MPFR_RNDD) != 0) return ref;
    mpfr_set_str(high.get(), text.c_str(), 10, MPFR_RNDU);
    round_to_grid(low.get());
    round_to_grid(high.get());
    ref.valid_syntax = true;
    ref.precision = precision;
    // Both bounds beyond the same end of the range: so is the exact value.
    const bool low_fits = mpfr_fits_intmax_p(low.get(), MPFR_RNDN) != 0;
    const bool high_fits = mpfr_fits_intmax_p(high.get(), MPFR_RNDN) != 0;
    if (!low_fits && !high_fits && mpfr_sgn(low.get()) == mpfr_sgn(high.get())) return ref;
    if (mpfr_equal_p(low.get(), high.get()) != 0) {
      ref.in_range = true;
      ref.raw = static_cast<std::int64_t>(mpfr_get_sj(low.get(), MPFR_RNDN));
      return ref;
    }
  }
  ADD_FAILURE() << "MPFR bounds never agreed for '" << text << "'";
  return ref;
}

std::string random_digits(std::mt19937_64& rng, std::size_t n) {
  std::string digits;
  const auto style = rng() % 4;  // uniform, mostly 0, mostly 9, runs
  for (std::size_t i = 0; i < n; ++i) {
    const auto roll = rng() % 10;
    char c = static_cast<char>('0' + rng() % 10);
    if (style == 1 && roll < 8) c = '0';
    if (style == 2 && roll < 8) c = '9';
    if (style == 3 && i > 0 && roll < 7) c = digits.back();
    digits += c;
  }
  return digits;
}

std::string random_exponent_text(std::mt19937_64& rng, std::int64_t exponent) {
  std::string text = rng() % 2 == 0 ? "e" : "E";
  if (exponent < 0) {
    text += '-';
  } else if (rng() % 3 == 0) {
    text += '+';
  }
  if (rng() % 8 == 0) text += std::string(rng() % 5, '0');
  text += std::to_string(exponent < 0 ? -exponent : exponent);
  return text;
}

// A random decimal in Fixed::parse's grammar: up to 40 digits, a point anywhere or nowhere, an
// exponent that mostly puts the leading digit between 10^-15 and 10^11 (in range, at the range's
// edge, and below one ulp) and sometimes anywhere up to 10^+-9 digits away.
std::string random_decimal(std::mt19937_64& rng) {
  std::string text;
  const auto sign = rng() % 3;
  if (sign == 1) text += '-';
  if (sign == 2) text += '+';
  const std::size_t n = 1 + rng() % 40;
  std::string digits = random_digits(rng, n);
  const auto point = static_cast<std::int64_t>(rng() % (n + 1));
  const bool has_point = rng() % 4 != 0;
  text += has_point ? with_point(digits, static_cast<std::size_t>(point)) : digits;
  const std::int64_t integer_digits = has_point ? point : static_cast<std::int64_t>(n);
  const auto kind = rng() % 10;
  if (kind < 2) return text;  // no exponent
  std::int64_t exponent = 0;
  if (kind < 8) {
    exponent = static_cast<std::int64_t>(rng() % 27) - 15 - integer_digits;
  } else if (kind < 9) {
    exponent = static_cast<std::int64_t>(rng() % 81) - 60;
  } else {
    exponent = static_cast<std::int64_t>(rng() % 2000000001) - 1000000000;
  }
  return text + random_exponent_text(rng, exponent);
}

// (2r + 1) / 2^33, the midpoint between two neighbours, written exactly (33 places), then kept,
// nudged up or down by 10^-40 or less, or rewritten with an exponent.
std::string random_midpoint(std::mt19937_64& rng) {
  const std::uint64_t r = rng() >> (rng() % 64);
  Integer scaled;
  mpz_set_ui(scaled.get(), 5);
  mpz_pow_ui(scaled.get(), scaled.get(), 33);
  Integer twice;
  mpz_set_ui(twice.get(), static_cast<unsigned long>(r));
  mpz_mul_2exp(twice.get(), twice.get(), 1);
  mpz_add_ui(twice.get(), twice.get(), 1);
  mpz_mul(scaled.get(), scaled.get(), twice.get());
  std::string digits = scaled.decimal();
  if (digits.size() < 34) digits = std::string(34 - digits.size(), '0') + digits;
  std::size_t places = 33;
  const auto nudge = rng() % 3;
  if (nudge == 1) {
    const std::string tail = std::string(rng() % 7, '0') + "1";
    digits += tail;
    places += tail.size();
  }
  if (nudge == 2) {
    digits.back() = '4';
    const std::string tail(1 + rng() % 7, '9');
    digits += tail;
    places += tail.size();
  }
  std::string text = rng() % 2 == 0 ? "-" : "";
  if (rng() % 2 == 0) {
    return text + with_point(digits, digits.size() - places);
  }
  // All digits after the point, then e+k with k the count of integer digits.
  const std::size_t integer_digits = digits.size() - places;
  return text + "0." + digits +
         random_exponent_text(rng, static_cast<std::int64_t>(integer_digits));
}

TEST(DecimalMpfr, ParseMatchesMpfrOnRandomDecimals) {
  std::mt19937_64 rng(20240611);
  std::size_t in_range = 0;
  std::size_t out_of_range = 0;
  std::size_t nonzero = 0;
  std::size_t needed_more_precision = 0;
  const std::size_t count = test::scaled(1200000);
  for (std::size_t i = 0; i < count; ++i) {
    const std::string text = i % 6 == 5 ? random_midpoint(rng) : random_decimal(rng);
    const Reference ref = mpfr_reference(text);
    ASSERT_TRUE(ref.valid_syntax) << "MPFR rejects '" << text << "'";
    if (ref.precision > 128) ++needed_more_precision;
    const ParseResult got = Fixed::parse(text);
    if (ref.in_range) {
      ++in_range;
      if (ref.raw != 0) ++nonzero;
      ASSERT_TRUE(got.ok()) << "'" << text << "': " << describe(got.error);
      ASSERT_EQ(got.value, Fixed::from_raw(ref.raw)) << "'" << text << "'";
    } else {
      ++out_of_range;
      ASSERT_EQ(got.error, ParseError::out_of_range)
          << "'" << text << "' parsed to " << ::testing::PrintToString(got.value);
    }
  }
  std::printf("%zu decimals: %zu in range (%zu nonzero), %zu out of range, %zu needed > 128 bits\n",
              count, in_range, nonzero, out_of_range, needed_more_precision);
  EXPECT_GT(nonzero, count / 2);
  EXPECT_GT(out_of_range, count / 20);
}

// The spec of to_string, from MPFR: for k = 0, 1, ... places, the k-place decimals just below and
// above x (floor and ceil of x 10^k); those that MPFR rounds back to x; the first k with any wins,
// the nearer of two (an exact tie: the even one).
std::string mpfr_shortest(std::int64_t raw) {
  Real x(128);
  mpfr_set_sj_2exp(x.get(), raw, -Fixed::fraction_bits, MPFR_RNDN);  // exact
  for (int places = 0; places <= 12; ++places) {
    Real scaled(256);
    mpfr_mul_ui(scaled.get(), x.get(), 1, MPFR_RNDN);
    for (int i = 0; i < places; ++i)
      mpfr_mul_ui(scaled.get(), scaled.get(), 10, MPFR_RNDN);
    Real below(256);
    Real above(256);
    mpfr_floor(below.get(), scaled.get());
    mpfr_ceil(above.get(), scaled.get());
    std::string best;
    Real best_distance(256);
    bool best_even = false;
    for (mpfr_ptr candidate : {below.get(), above.get()}) {
      Integer m;
      mpfr_get_z(m.get(), candidate, MPFR_RNDN);
      const bool negative = mpz_sgn(m.get()) < 0;
      mpz_abs(m.get(), m.get());
      std::string digits = m.decimal();
      const auto width = static_cast<std::size_t>(places) + 1;
      if (digits.size() < width) digits = std::string(width - digits.size(), '0') + digits;
      if (places > 0) digits = with_point(digits, digits.size() - width + 1);
      const std::string text = (negative ? "-" : "") + digits;
      const Reference ref = mpfr_reference(text);
      if (!ref.in_range || ref.raw != raw) continue;
      Real distance(256);
      mpfr_sub(distance.get(), candidate, scaled.get(), MPFR_RNDN);  // exact at 256 bits
      mpfr_abs(distance.get(), distance.get(), MPFR_RNDN);
      const bool even = mpz_even_p(m.get()) != 0;
      const int order = best.empty() ? -1 : mpfr_cmp(distance.get(), best_distance.get());
      if (order < 0 || (order == 0 && even && !best_even)) {
        best = text;
        mpfr_set(best_distance.get(), distance.get(), MPFR_RNDN);
        best_even = even;
      }
    }
    if (!best.empty()) return best;
  }
  ADD_FAILURE() << "no decimal with up to 12 places rounds back to raw " << raw;
  return "";
}

TEST(DecimalMpfr, ToStringIsTheShortestNearestDecimal) {
  std::mt19937_64 rng(77);
  const std::size_t count = test::scaled(300000);
  std::size_t max_places = 0;
  for (std::size_t i = 0; i < count; ++i) {
    std::uint64_t bits = rng();
    if (i % 4 == 1) bits >>= rng() % 64;
    if (i % 4 == 2) bits = (bits & ~std::uint64_t{0xFFFFFFFF}) | (rng() % 1000 * 4294967ULL);
    // Many trailing zero bits: x 10^k can then end in exactly .5, a tie between two candidates.
    if (i % 4 == 3) bits &= ~((std::uint64_t{1} << (18 + rng() % 15)) - 1);
    if (i % 2 == 1) bits = 0U - bits;
    const auto raw = static_cast<std::int64_t>(bits);
    const std::string expected = mpfr_shortest(raw);
    const std::string got = to_string(Fixed::from_raw(raw));
    ASSERT_EQ(got, expected) << "raw " << raw;
    const std::size_t point = got.find('.');
    if (point != std::string::npos) max_places = std::max(max_places, got.size() - point - 1);
  }
  for (const std::int64_t raw :
       {std::int64_t{0}, std::int64_t{1}, std::int64_t{-1},
        std::numeric_limits<std::int64_t>::max(), std::numeric_limits<std::int64_t>::min()}) {
    EXPECT_EQ(to_string(Fixed::from_raw(raw)), mpfr_shortest(raw)) << "raw " << raw;
  }
  EXPECT_EQ(max_places, 10U);
}

}  // namespace
}  // namespace detsim

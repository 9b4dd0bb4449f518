// The mathematical constants of Fixed are the correctly rounded Q32.32 values: each is derived here
// with MPFR at 256 bits, scaled by 2^32 and rounded to the nearest integer (MPFR_RNDN, ties to
// even; none of these irrational values can be a tie).
#include <gtest/gtest.h>

#include <string>

#include <detsim_accuracy/mpfr.hpp>

namespace {

using detsim::Fixed;
using detsim::accuracy::Mp;

constexpr mpfr_prec_t precision = 256;

/// The nearest raw value of `value`, and a description of `value` and the bits for messages.
struct Expected {
  std::int64_t raw = 0;
  std::string exact;
};

Expected nearest(mpfr_srcptr value) {
  Mp scaled(precision);
  mpfr_mul_2ui(scaled.get(), value, 32, MPFR_RNDN);
  Expected e;
  e.exact = detsim::accuracy::to_decimal(value, 40);
  mpfr_rint(scaled.get(), scaled.get(), MPFR_RNDN);
  e.raw = static_cast<std::int64_t>(mpfr_get_sj(scaled.get(), MPFR_RNDN));
  return e;
}

void expect_correctly_rounded(const char* name, Fixed constant, mpfr_srcptr value) {
  const Expected e = nearest(value);
  EXPECT_EQ(constant.raw(), e.raw)
      << "Fixed::" << name << "() is " << detsim::accuracy::describe_fixed(constant)
      << "; the exact " << name << " is " << e.exact << ", nearest Q32.32 value "
      << detsim::accuracy::describe_fixed(Fixed::from_raw(e.raw));
  // The rounding error is below half an ulp, and strictly: an irrational is never a tie.
  Mp error(precision);
  Mp fixed_value(precision);
  detsim::accuracy::set_fixed(fixed_value.get(), Fixed::from_raw(e.raw));
  mpfr_sub(error.get(), fixed_value.get(), value, MPFR_RNDN);
  mpfr_mul_2ui(error.get(), error.get(), 33, MPFR_RNDN);  // 2 * error in ulp
  EXPECT_LT(mpfr_cmpabs_ui(error.get(), 1), 0) << name;
}

TEST(FixedConstants, Pi) {
  Mp v(precision);
  mpfr_const_pi(v.get(), MPFR_RNDN);
  expect_correctly_rounded("pi", Fixed::pi(), v.get());
}

TEST(FixedConstants, HalfPi) {
  Mp v(precision);
  mpfr_const_pi(v.get(), MPFR_RNDN);
  mpfr_div_2ui(v.get(), v.get(), 1, MPFR_RNDN);
  expect_correctly_rounded("half_pi", Fixed::half_pi(), v.get());
}

TEST(FixedConstants, TwoPi) {
  Mp v(precision);
  mpfr_const_pi(v.get(), MPFR_RNDN);
  mpfr_mul_2ui(v.get(), v.get(), 1, MPFR_RNDN);
  expect_correctly_rounded("two_pi", Fixed::two_pi(), v.get());
}

TEST(FixedConstants, E) {
  Mp v(precision);
  mpfr_set_ui(v.get(), 1, MPFR_RNDN);
  mpfr_exp(v.get(), v.get(), MPFR_RNDN);
  expect_correctly_rounded("e", Fixed::e(), v.get());
}

TEST(FixedConstants, Ln2) {
  Mp v(precision);
  mpfr_const_log2(v.get(), MPFR_RNDN);
  expect_correctly_rounded("ln2", Fixed::ln2(), v.get());
}

TEST(FixedConstants, Sqrt2) {
  Mp v(precision);
  mpfr_sqrt_ui(v.get(), 2, MPFR_RNDN);
  expect_correctly_rounded("sqrt2", Fixed::sqrt2(), v.get());
}

}  // namespace

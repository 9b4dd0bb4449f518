#include <detsim_accuracy/mpfr.hpp>

#include <cinttypes>
#include <cstdio>

namespace detsim::accuracy {

void use_widest_exponent_range() {
  mpfr_set_emin(mpfr_get_emin_min());
  mpfr_set_emax(mpfr_get_emax_max());
}

void set_fixed(mpfr_ptr out, Fixed x) {
  // Both steps are exact: a 64-bit integer fits in the precision, and dividing by a power of two
  // only changes the exponent.
  mpfr_set_sj(out, static_cast<intmax_t>(x.raw()), MPFR_RNDN);
  mpfr_div_2ui(out, out, Fixed::fraction_bits, MPFR_RNDN);
}

Fixed round_to_fixed(mpfr_srcptr value, mpfr_ptr scratch, bool* tie) {
  // Scaling by 2^32 is exact, so rounding to an integer (MPFR_RNDN: nearest, ties to even) is
  // rounding to the Q32.32 grid.
  mpfr_mul_2ui(scratch, value, Fixed::fraction_bits, MPFR_RNDN);
  if (tie != nullptr) {
    // Halfway iff the scaled value is not an integer but twice it is (both steps exact).
    const bool integer = mpfr_integer_p(scratch) != 0;
    mpfr_mul_2ui(scratch, scratch, 1, MPFR_RNDN);
    *tie = !integer && mpfr_integer_p(scratch) != 0;
    mpfr_div_2ui(scratch, scratch, 1, MPFR_RNDN);
  }
  mpfr_rint(scratch, scratch, MPFR_RNDN);
  if (mpfr_fits_intmax_p(scratch, MPFR_RNDN) == 0) {
    return mpfr_sgn(scratch) > 0 ? Fixed::max() : Fixed::min();
  }
  return Fixed::from_raw(static_cast<std::int64_t>(mpfr_get_sj(scratch, MPFR_RNDN)));
}

std::string to_decimal(mpfr_srcptr value, int digits) {
  char buffer[128];
  mpfr_snprintf(buffer, sizeof buffer, "%.*Rg", digits, value);
  return buffer;
}

std::string describe_fixed(Fixed x, int digits) {
  Mp value;
  set_fixed(value.get(), x);
  char raw[32];
  std::snprintf(raw, sizeof raw, "0x%016" PRIx64, static_cast<std::uint64_t>(x.raw()));
  return to_decimal(value.get(), digits) + " (raw " + raw + ")";
}

}  // namespace detsim::accuracy

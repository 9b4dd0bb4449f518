#include <detsim_accuracy/check.hpp>

#include <limits>

namespace detsim::accuracy {

Checker::Checker() {
  set_fixed(max_.get(), Fixed::max());
  set_fixed(min_.get(), Fixed::min());
  mpfr_set_ui_2exp(large_.get(), 1, large_threshold_log2, MPFR_RNDN);
}

Verdict Checker::check(Contract contract, Fixed result, mpfr_srcptr exact) {
  Verdict verdict;
  set_fixed(result_.get(), result);

  // |result - v| at the reference precision: off by at most 2^-160 relative, far below any bound.
  mpfr_sub(difference_.get(), result_.get(), exact, MPFR_RNDN);
  mpfr_abs(difference_.get(), difference_.get(), MPFR_RNDN);
  mpfr_mul_2ui(scratch_.get(), difference_.get(), Fixed::fraction_bits, MPFR_RNDN);
  verdict.error_ulp = mpfr_get_d(scratch_.get(), MPFR_RNDN);
  if (mpfr_zero_p(exact) != 0) {
    verdict.relative =
        mpfr_zero_p(difference_.get()) != 0 ? 0.0 : std::numeric_limits<double>::infinity();
  } else {
    mpfr_div(scratch_.get(), difference_.get(), exact, MPFR_RNDN);
    verdict.relative = mpfr_get_d(scratch_.get(), MPFR_RNDN);
    if (verdict.relative < 0) verdict.relative = -verdict.relative;
  }

  const bool above = mpfr_cmp(exact, max_.get()) > 0;
  const bool below = mpfr_cmp(exact, min_.get()) < 0;
  if (above || below) {
    verdict.region = Region::beyond;
  } else {
    verdict.region = mpfr_cmpabs(exact, large_.get()) < 0 ? Region::small : Region::large;
  }

  if (contract == Contract::correctly_rounded) {
    // One exact comparison decides it: the result must be the grid point MPFR rounds v to.
    verdict.expected = round_to_fixed(exact, scratch_.get(), &verdict.tie);
    verdict.pass = result == verdict.expected;
    if (!verdict.pass) {
      verdict.why = verdict.region == Region::beyond ? "not saturated"
                    : verdict.tie                    ? "not the even neighbour of a tie"
                                                     : "not correctly rounded";
    }
    return verdict;
  }

  // Faithful: relative error < 2^-46 is |result - v| * 2^46 < |v|.
  mpfr_mul_2si(scratch_.get(), difference_.get(), -relative_bound_log2, MPFR_RNDN);
  const bool relative_ok = mpfr_cmpabs(scratch_.get(), exact) < 0;
  switch (verdict.region) {
    case Region::beyond:
      verdict.pass = result == (above ? Fixed::max() : Fixed::min()) || relative_ok;
      verdict.why = "beyond the Fixed range but not saturated";
      break;
    case Region::large:
      verdict.pass = relative_ok;
      verdict.why = "relative error >= 2^-46";
      break;
    case Region::small:
      // error_ulp < 1, decided exactly.
      verdict.pass = mpfr_cmp_ui_2exp(difference_.get(), 1, -Fixed::fraction_bits) < 0;
      verdict.why = "error >= 1 ulp";
      break;
  }
  if (verdict.pass) verdict.why = "";
  return verdict;
}

}  // namespace detsim::accuracy

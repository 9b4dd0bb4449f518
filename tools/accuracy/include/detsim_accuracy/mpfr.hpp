// MPFR, included the one way the accuracy tools use it, and the few helpers every reference
// computation needs. MPFR never reaches the detsim libraries: this lives in tools/ only.
#pragma once

#include <cstdint>
#include <string>

// <cstdint> first and MPFR_USE_INTMAX_T so that mpfr.h declares mpfr_set_sj / mpfr_get_sj.
#ifndef MPFR_USE_INTMAX_T
#define MPFR_USE_INTMAX_T 1
#endif
#include <mpfr.h>

#include <detsim/fixed/fixed.hpp>

namespace detsim::accuracy {

/// Precision of every reference value, in bits. Q32.32 values need 64 bits, a product of two 128,
/// lerp's exact a + (b - a) t 130; the remaining margin makes the rounding of the reference itself
/// (2^-160 relative) invisible next to the 2^-32 grid it is compared with.
inline constexpr mpfr_prec_t reference_precision = 160;

/// An mpfr_t that initialises and clears itself. Not copyable: allocate once, reuse per sample.
class Mp {
 public:
  explicit Mp(mpfr_prec_t precision = reference_precision) { mpfr_init2(value_, precision); }
  ~Mp() { mpfr_clear(value_); }
  Mp(const Mp&) = delete;
  Mp& operator=(const Mp&) = delete;

  [[nodiscard]] mpfr_ptr get() noexcept { return value_; }
  [[nodiscard]] mpfr_srcptr get() const noexcept { return value_; }

 private:
  mpfr_t value_;
};

/// Widens MPFR's exponent range (for this thread) to the largest it supports, so that no reference
/// value overflows to infinity or underflows to zero: e^-(2^31) must stay a positive number for
/// "0 or one ulp" to be judged right. measure() calls it.
void use_widest_exponent_range();

/// out = x exactly (raw / 2^32): mpfr_set_sj, then a division by 2^32, both exact at >= 64 bits.
void set_fixed(mpfr_ptr out, Fixed x);

/// The value rounded to the Q32.32 grid, to nearest with ties to even (MPFR_RNDN), then saturated
/// to [Fixed::min(), Fixed::max()]. `tie` (optional) is set when the value lies exactly halfway
/// between two grid points. `scratch` must have at least the precision of `value`.
[[nodiscard]] Fixed round_to_fixed(mpfr_srcptr value, mpfr_ptr scratch, bool* tie = nullptr);

/// A value in decimal with `digits` significant digits ("%.*Rg").
[[nodiscard]] std::string to_decimal(mpfr_srcptr value, int digits = 25);

/// A Fixed as "decimal (raw 0x...)": the decimal has 20 significant digits and the raw bits are
/// the exact two's-complement value, as the test printers show it.
[[nodiscard]] std::string describe_fixed(Fixed x, int digits = 20);

}  // namespace detsim::accuracy

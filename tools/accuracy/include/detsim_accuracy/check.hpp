// The contract check for one result against its MPFR reference: the rule that decides pass or
// fail, shared by the accuracy test, `detsim accuracy`, and the harness's own tests.
#pragma once

#include <detsim_accuracy/accuracy.hpp>
#include <detsim_accuracy/mpfr.hpp>

namespace detsim::accuracy {

/// Where the exact value lies, which decides the rule applied.
enum class Region : std::uint8_t {
  small,   ///< |v| < 2^16
  large,   ///< 2^16 <= |v|, within [Fixed::min(), Fixed::max()]
  beyond,  ///< v > Fixed::max() or v < Fixed::min(): the result must saturate
};

struct Verdict {
  Region region = Region::small;
  bool pass = false;
  double error_ulp = 0;  ///< |result - v| * 2^32
  double relative = 0;   ///< |result - v| / |v|; 0 when both are 0, +inf when only v is
  bool tie = false;      ///< correctly rounded only: v is exactly halfway between two values
  Fixed expected;        ///< correctly rounded only: v rounded (ties to even) and saturated
  const char* why = "";  ///< when !pass: the rule broken, in a few words
};

/// Checks results against exact values. Holds its MPFR temporaries, so one Checker serves every
/// sample of a run without allocating.
class Checker {
 public:
  Checker();

  /// Judges `result` against the exact value `exact` (not NaN) under `contract`. All comparisons
  /// are made in MPFR; the doubles in the verdict are for reports only.
  [[nodiscard]] Verdict check(Contract contract, Fixed result, mpfr_srcptr exact);

 private:
  Mp result_;
  Mp difference_;
  Mp scratch_;
  Mp max_;    // Fixed::max() exactly
  Mp min_;    // Fixed::min() exactly
  Mp large_;  // 2^16
};

}  // namespace detsim::accuracy

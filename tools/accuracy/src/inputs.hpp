// Input generation for the accuracy harness: a seeded generator, the random distributions, and
// the helpers that build lists of edge inputs. Internal to detsim_accuracy.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include <detsim/fixed/fixed.hpp>
#include <detsim_accuracy/mpfr.hpp>

namespace detsim::accuracy::detail {

using Args = std::array<Fixed, 3>;
using ArgsList = std::vector<Args>;

inline constexpr std::int64_t raw_one = Fixed::one_raw;
inline constexpr std::int64_t raw_max = Fixed::max().raw();
inline constexpr std::int64_t raw_min = Fixed::min().raw();

/// splitmix64 (Steele, Lea, Flood 2014): a 64-bit state, full period, good enough to spread
/// test inputs, and the same sequence on every machine.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) noexcept : state_(seed) {}

  std::uint64_t next() noexcept {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15U);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9U;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBU;
    return z ^ (z >> 31);
  }
  bool coin() noexcept { return (next() >> 63) != 0; }
  /// Uniform in [0, n) for n > 0 (Lemire's multiply-high; the bias is below 2^-64 * n).
  std::uint64_t below(std::uint64_t n) noexcept;
  /// Uniform raw value in [lo, hi].
  std::int64_t uniform(std::int64_t lo, std::int64_t hi) noexcept;
  /// A magnitude whose highest set bit is uniform in [low_bit, high_bit] (<= 62) and whose lower
  /// bits are uniform: log-uniform by binade.
  std::uint64_t log_magnitude(int low_bit, int high_bit) noexcept;
  /// log_magnitude with a random sign.
  std::int64_t log_signed(int low_bit, int high_bit) noexcept;

 private:
  std::uint64_t state_;
};

/// The per-function stream: the run's seed mixed with the function's name.
[[nodiscard]] std::uint64_t stream_seed(std::uint64_t seed, std::string_view name) noexcept;

[[nodiscard]] constexpr Fixed raw(std::int64_t r) noexcept {
  return Fixed::from_raw(r);
}
/// `sign * magnitude` for magnitudes below 2^63.
[[nodiscard]] std::int64_t with_sign(bool negative, std::uint64_t magnitude) noexcept;

/// raw + d when that stays within the int64 range.
[[nodiscard]] bool offset(std::int64_t raw, std::int64_t d, std::int64_t* out) noexcept;

// ---- Edge list builders ------------------------------------------------------------------------

/// Adds f(raw + d) for every d in [-radius, radius] that stays in range.
void add_around(ArgsList& list, std::int64_t center, std::int64_t radius);
/// Adds raw + d and raw - d for d = 2^0 .. 2^max_log2 and 2^j +- 1: sweeps the distance from a
/// threshold over every scale.
void add_sweep(ArgsList& list, std::int64_t center, int max_log2);
/// Adds v and -v for each raw value (min() has no negation and is added as is).
void add_both_signs(ArgsList& list, std::int64_t value);

/// Special values for one argument: 0, +-1 and +-2 ulp, +-1/2, +-1 and neighbours, +-2, +-3,
/// +-pi, powers of two 2^-32 .. 2^30 of both signs with their raw neighbours, max, min and their
/// neighbours. Includes out-of-domain values; the domain check handles them.
[[nodiscard]] std::vector<std::int64_t> special_values();
/// A smaller set for the cross products of two- and three-argument functions.
[[nodiscard]] std::vector<std::int64_t> special_values_small();

/// Nearest raw value to `value` (ties to even), saturated.
[[nodiscard]] std::int64_t nearest_raw(mpfr_srcptr value);

/// Multiples of pi/2 in the Fixed range: the raw values nearest k pi/2 for a spread of k up to
/// the range end (small k, the largest k, powers of two, random k, and the k whose multiple
/// lies closest to a Q32.32 value: continued-fraction denominators of pi 2^31 and their small
/// multiples). Each entry is (k, nearest raw of k pi/2).
struct HalfPiMultiple {
  std::uint64_t k;
  std::int64_t raw;
};
[[nodiscard]] std::vector<HalfPiMultiple> half_pi_multiples();

}  // namespace detsim::accuracy::detail

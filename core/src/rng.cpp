#include <detsim/core/rng.hpp>
#include <detsim/fixed/wide.hpp>

namespace detsim {

std::uint64_t Rng::below(std::uint64_t bound) noexcept {
  if (bound == 0) return 0;
  // Lemire, "Fast random integer generation in an interval" (2019): the high word of x * bound is
  // uniform over [0, bound) once the low words below 2^64 mod bound are rejected.
  wide::U128 product = wide::Default::mul(next_u64(), bound);
  if (product.lo < bound) {
    const std::uint64_t threshold = (0U - bound) % bound;
    while (product.lo < threshold)
      product = wide::Default::mul(next_u64(), bound);
  }
  return product.hi;
}

std::int64_t Rng::range(std::int64_t low, std::int64_t high) noexcept {
  if (high <= low) return low;
  const std::uint64_t span = static_cast<std::uint64_t>(high) - static_cast<std::uint64_t>(low);
  const std::uint64_t offset = span == ~std::uint64_t{0} ? next_u64() : below(span + 1);
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(low) + offset);
}

Fixed Rng::uniform(Fixed low, Fixed high) noexcept {
  if (high <= low) return low;
  const std::int64_t raw = range(low.raw(), high.raw() - 1);
  return Fixed::from_raw(raw);
}

Vec3 Rng::unit_vector() noexcept {
  // Points uniform in the cube [-1, 1)^3, kept when inside the unit ball (and not too near the
  // centre, where normalising would magnify the grid), are uniform in direction. Acceptance is
  // about 52%, so the loop ends after ~2 tries on average; it is bounded only in probability, as
  // every rejection sampler is, and draws the same numbers on every machine.
  const Fixed min_length_squared = Fixed::from_raw(Fixed::one_raw >> 8);
  for (;;) {
    const Vec3 p{uniform(-Fixed::one(), Fixed::one()), uniform(-Fixed::one(), Fixed::one()),
                 uniform(-Fixed::one(), Fixed::one())};
    const Fixed l2 = length_squared(p);
    if (l2 <= Fixed::one() && l2 >= min_length_squared) return normalize(p);
  }
}

}  // namespace detsim

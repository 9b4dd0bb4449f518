// Lengths, distances and normalisation of Vec2 and Vec3: everything that needs a square root.
#include <array>
#include <cstdint>

#include <detsim/fixed/vec2.hpp>
#include <detsim/fixed/vec3.hpp>

#include "isqrt.hpp"
#include "normalize.hpp"

namespace detsim {
namespace {

/// a - b as sign and 64-bit magnitude: exact, since |a - b| < 2^64 for any two raws.
std::uint64_t difference_magnitude(Fixed a, Fixed b) noexcept {
  const auto ua = static_cast<std::uint64_t>(a.raw());
  const auto ub = static_cast<std::uint64_t>(b.raw());
  return a < b ? ub - ua : ua - ub;  // modulo 2^64, exact because the true difference fits
}

/// Raw bits of sqrt(d_0^2 + ... ) for exact magnitudes d_i < 2^64, saturated to INT64_MAX. The sum
/// of squares can exceed 2^128 only when the root is above 2^64, so a carry out means saturation.
template <std::size_t N>
Fixed length_of_magnitudes(const std::array<std::uint64_t, N>& d) noexcept {
  wide::U128 sum{};
  for (const std::uint64_t di : d) {
    const wide::U128 square = wide::Default::mul(di, di);
    sum = wide::add(sum, square);
    if (wide::less(sum, square)) return Fixed::max();
  }
  const std::uint64_t root = detail::isqrt_round(sum);
  return root > static_cast<std::uint64_t>(detail::raw_max)
             ? Fixed::max()
             : Fixed::from_raw(static_cast<std::int64_t>(root));
}

}  // namespace

Fixed length(Vec2 v) noexcept {
  return Fixed::from_raw(detail::hypot_raw(v.x.raw(), v.y.raw()));
}

Fixed length(Vec3 v) noexcept {
  return Fixed::from_raw(detail::hypot_raw(v.x.raw(), v.y.raw(), v.z.raw()));
}

Fixed distance(Vec2 a, Vec2 b) noexcept {
  return length_of_magnitudes(
      std::array{difference_magnitude(a.x, b.x), difference_magnitude(a.y, b.y)});
}

Fixed distance(Vec3 a, Vec3 b) noexcept {
  return length_of_magnitudes(std::array{difference_magnitude(a.x, b.x),
                                         difference_magnitude(a.y, b.y),
                                         difference_magnitude(a.z, b.z)});
}

Vec2 normalize_or(Vec2 v, Vec2 fallback) noexcept {
  std::array c{v.x.raw(), v.y.raw()};
  if (!detail::normalize_raw(c)) return fallback;
  return {Fixed::from_raw(c[0]), Fixed::from_raw(c[1])};
}

Vec3 normalize_or(Vec3 v, Vec3 fallback) noexcept {
  std::array c{v.x.raw(), v.y.raw(), v.z.raw()};
  if (!detail::normalize_raw(c)) return fallback;
  return {Fixed::from_raw(c[0]), Fixed::from_raw(c[1]), Fixed::from_raw(c[2])};
}

Vec2 normalize(Vec2 v) noexcept {
  return normalize_or(v, Vec2::zero());
}
Vec3 normalize(Vec3 v) noexcept {
  return normalize_or(v, Vec3::zero());
}

}  // namespace detsim

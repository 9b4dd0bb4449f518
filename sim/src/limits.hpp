// The limits of what the simulation accepts (docs/SIM.md, "What is refused"), and the arithmetic
// that checks derived quantities against them. Internal to detsim::sim.
//
// Q32.32 saturates at about +-2^31: a mass, a moment of inertia or a force that reaches the top
// of the range is no longer the quantity the user asked for, and every product it enters is
// wrong too. Rather than cap such values silently, definitions and calls whose derived
// quantities would leave these limits are refused, with a message naming the quantity, the
// value it would have and the limit.
#pragma once

#include <cstdint>
#include <limits>
#include <string>

#include <detsim/fixed/fixed.hpp>

namespace detsim::sim_detail {

/// Every quantity that a definition or call derives (volume, mass, moments of inertia and their
/// inverses, accumulated forces and torques, moments of forces, rim speeds) stays within
/// +-(2^31 - 1): the top of the Q32.32 range less one, so that any value that saturated (to about
/// +-2^31) is above it.
inline constexpr Fixed max_quantity = Fixed::from_int(std::numeric_limits<std::int32_t>::max());
/// Positions (m) and velocities (m/s, rad/s), per component: half the range, so that a position
/// plus the travel of a step (velocity * dt, dt <= 1) plus a bounding box (shapes are at most
/// 10^4 m) stays inside it.
inline constexpr Fixed max_position = Fixed::from_int(1 << 30);
inline constexpr Fixed max_velocity = Fixed::from_int(1 << 30);
/// Accelerations that forces and torques give (m/s^2 per component, rad/s^2 as |torque| over the
/// smallest moment of inertia): half the range, leaving room for gravity (at most 10^5 m/s^2) and
/// for any orientation of the body (a world-space component is at most the vector's length).
inline constexpr Fixed max_acceleration = Fixed::from_int(1 << 30);
/// The smallest mass (kg) and moment of inertia (kg m^2) of a dynamic body: 3 ulp, the smallest
/// values whose inverses (1 / x, about 1.43e9) are within max_quantity. 2 ulp has the inverse 2^31,
/// which saturates.
inline constexpr Fixed min_mass = Fixed::from_raw(3);

/// |x| > limit, for a limit >= 0 (no negation, so Fixed::min() needs no care).
[[nodiscard]] constexpr bool beyond(Fixed x, Fixed limit) noexcept {
  return x > limit || x < -limit;
}

/// Fixed arithmetic that remembers whether any result on the way left +-max_quantity (an
/// intermediate that saturated included). Its values are Fixed's bit for bit, so a quantity
/// computed with it is the one the simulation uses, and a formula written once for both types
/// (the shapes' volumes and moments of inertia) cannot be checked differently from how it is
/// computed.
class Checked {
 public:
  constexpr Checked() noexcept = default;
  // NOLINTNEXTLINE(google-explicit-constructor): Fixed operands mix in like Fixed's own.
  constexpr Checked(Fixed v) noexcept : v_(v), over_(beyond(v, max_quantity)) {}

  [[nodiscard]] constexpr Fixed value() const noexcept { return v_; }
  /// Whether this value, or any it was computed from, is beyond +-max_quantity.
  [[nodiscard]] constexpr bool over() const noexcept { return over_; }

  friend constexpr Checked operator+(Checked a, Checked b) noexcept {
    return {a.v_ + b.v_, a.over_ || b.over_};
  }
  friend constexpr Checked operator-(Checked a, Checked b) noexcept {
    return {a.v_ - b.v_, a.over_ || b.over_};
  }
  friend constexpr Checked operator*(Checked a, Checked b) noexcept {
    return {a.v_ * b.v_, a.over_ || b.over_};
  }
  friend constexpr Checked operator/(Checked a, Checked b) noexcept {
    return {a.v_ / b.v_, a.over_ || b.over_};
  }

 private:
  constexpr Checked(Fixed v, bool inherited) noexcept
      : v_(v), over_(inherited || beyond(v, max_quantity)) {}

  Fixed v_;
  bool over_ = false;
};

/// "<quantity> would be <value> <unit>, above the limit <limit> <unit>": the common wording of a
/// refused derived quantity. A value that saturated is reported as such ("would be at least
/// 2147483648"), and one whose formula left the range only on the way as that.
[[nodiscard]] std::string above_limit(const std::string& quantity, Checked value, Fixed limit,
                                      const char* unit);

}  // namespace detsim::sim_detail

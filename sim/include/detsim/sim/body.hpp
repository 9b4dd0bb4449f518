// Bodies: IDs, types and the definition a body is created from.
#pragma once

#include <compare>
#include <cstdint>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/shape.hpp>

namespace detsim {

/// A body's identity: a value, never reused within a world, assigned in creation order (1, 2,
/// 3, ...). Zero is the null ID. Everything the simulation iterates goes in ascending ID order.
struct BodyId {
  std::uint32_t value = 0;

  [[nodiscard]] constexpr bool is_null() const noexcept { return value == 0; }
  friend constexpr auto operator<=>(BodyId, BodyId) noexcept = default;
};

/// The numeric values are part of the canonical state encoding.
enum class BodyType : std::uint8_t {
  static_body = 0,  ///< never moves; infinite mass
  kinematic = 1,    ///< moved by its velocity only; pushes dynamic bodies, is not pushed
  dynamic = 2,      ///< moved by forces, gravity and contacts
};

/// Everything needed to create a body. Plain data with defaults; recordable.
/// World axes along which a dynamic body may not move (BodyDef::lock_translation) or about which
/// it may not turn (BodyDef::lock_rotation). The solver treats a locked axis as infinite mass or
/// inertia along it, exactly: no impulse, force, gravity or push moves the body that way, and a
/// velocity component along it (one set with the body, or later) is dropped at the next step. A
/// planar game (2D in 3D) locks z translation and x and y rotation; an upright character locks
/// rotation about x and z. Saved and hashed (the body's lock_* fields).
struct AxisLocks {
  bool x = false;
  bool y = false;
  bool z = false;

  [[nodiscard]] constexpr bool any() const noexcept { return x || y || z; }
  friend constexpr bool operator==(AxisLocks, AxisLocks) noexcept = default;
};

struct BodyDef {
  BodyType type = BodyType::dynamic;
  Shape shape = Shape::sphere(Fixed::half());
  Vec3 position{};
  /// Must be a unit quaternion: | |q|^2 - 1 | <= 2^-20. Use normalize() or from_axis_angle().
  Quat orientation{};
  Vec3 linear_velocity{};   ///< m/s
  Vec3 angular_velocity{};  ///< rad/s, world space
  /// kg. When zero, the mass is density * volume. Dynamic bodies must end up with a positive mass.
  Fixed mass{};
  Fixed density = Fixed::from_int(1000);  ///< kg/m^3 (water), used when mass is zero
  /// Coulomb coefficient, >= 0. 0.6 rounded down to the Q32.32 grid, the value every run and
  /// golden file has used (0.6_fx rounds to nearest, one ulp above).
  Fixed friction = 0.5999999999_fx;
  Fixed restitution{};      ///< 0 (no bounce) .. 1 (elastic)
  Fixed linear_damping{};   ///< 1/s, >= 0: velocity *= 1 / (1 + dt * damping) per step
  Fixed angular_damping{};  ///< 1/s, >= 0
  /// Collision filtering: a and b collide when (a.layer & b.mask) and (b.layer & a.mask).
  std::uint32_t layer = 1;
  std::uint32_t mask = 0xFFFFFFFFU;
  bool sensor = false;           ///< reports overlaps as events, makes no contact response
  bool ccd = false;              ///< continuous collision against everything, whatever its speed
  AxisLocks lock_translation{};  ///< world axes the body does not move along
  AxisLocks lock_rotation{};     ///< world axes the body does not turn about
  std::uint64_t user_data = 0;

  friend constexpr bool operator==(const BodyDef&, const BodyDef&) noexcept = default;
};

}  // namespace detsim

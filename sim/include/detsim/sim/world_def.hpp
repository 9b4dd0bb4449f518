// WorldDef: the configuration a World is created from. Plain data with defaults; every field is
// part of the saved state and of a replay's fingerprint.
#pragma once

#include <cstdint>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/vec3.hpp>

namespace detsim {

struct WorldDef {
  /// m/s^2.
  Vec3 gravity{Fixed::zero(), -9.81_fx, Fixed::zero()};
  /// Seconds per step, > 0 and <= 1: 1/60 s rounded to the nearest Q32.32 value.
  Fixed dt = 1_fx / 60_fx;
  /// Sub-steps per step (1..64): the contact solver integrates and solves this many times per step.
  std::uint32_t substeps = 4;
  /// Velocity iterations per sub-step (1..64), and as many relaxation iterations.
  std::uint32_t iterations = 1;
  /// Seeds the world's RNG.
  std::uint64_t seed = 0;

  /// Speeds are clamped to these after every velocity update (m/s, rad/s; > 0).
  Fixed max_linear_speed = Fixed::from_int(1500);
  Fixed max_angular_speed = Fixed::from_int(200);

  /// Soft contact constraints (Box2D v3's soft step): stiffness in Hz (> 0), damping ratio (>= 0),
  /// and the largest speed at which overlap is pushed apart (m/s, > 0).
  Fixed contact_hertz = Fixed::from_int(30);
  Fixed contact_damping_ratio = Fixed::from_int(10);
  Fixed contact_push_max = Fixed::from_int(3);
  /// Approach speeds below this (m/s, >= 0) get no restitution: resting contacts do not bounce.
  Fixed restitution_threshold = Fixed::one();
  /// Allowed overlap (m, >= 0) that is not pushed apart, so resting contacts persist.
  Fixed linear_slop = 0.000244140625_fx;  // 2^-12 m exactly, about 0.24 mm
  /// Contacts are created this far (m, >= 0) before the surfaces touch (speculative contacts).
  Fixed speculative_distance = Fixed::from_raw(Fixed::one_raw / 50);  // 2 cm, rounded down

  /// Sleeping: a body whose speeds stay below these for time_to_sleep seconds may sleep with its
  /// island (m/s, rad/s, s; all >= 0).
  bool enable_sleep = true;
  // 0.05, rounded down (0.05_fx would round up: these defaults keep the bits every run has used).
  Fixed sleep_linear_speed = Fixed::from_raw(Fixed::one_raw / 20);   // 5 cm/s
  Fixed sleep_angular_speed = Fixed::from_raw(Fixed::one_raw / 20);  // ~2.9 deg/s
  Fixed time_to_sleep = Fixed::half();

  friend constexpr bool operator==(const WorldDef&, const WorldDef&) noexcept = default;
};

/// The pair budget: in one step, a dynamic body takes part in at most this many pairs with other
/// dynamic bodies of comparable size (a bounding radius at least half its own), chosen in
/// ascending ID pair order; further pairs wait for a later step. It bounds the cost of bodies
/// spawned into one another (n of them at one point would make n^2 / 2 pairs). Ordinary scenes
/// stay far below it, and a large body carrying many small ones does not count them.
inline constexpr std::uint32_t pair_budget = 64;

/// The defaults are made for bodies about a metre across: a 2 cm contact range and a 0.24 mm
/// slop are larger than a millimetre body, and tiny beside a kilometre one; and a contact spring
/// of a given stiffness sags by g / omega^2 under its load whatever the body's size. This returns
/// `def` made for bodies of about `unit` metres (0.01 for centimetre parts, 1000 for kilometre
/// ones), so that the scene behaves like a metre scene (Box2D's lengthUnitsPerMeter):
/// - linear_slop, speculative_distance, contact_push_max and sleep_linear_speed times `unit`;
/// - contact_hertz divided by sqrt(unit), so that the sag is the same fraction of a body;
/// - substeps raised (up to 64) until the spring is no stiffer than a quarter of the sub-step
///   rate, the most the solver allows: for unit 0.01, 20 sub-steps; for 0.001, 64.
/// Gravity, the speed limits and the time step stay as they are: they are physics, not
/// tolerances. Below about a millimetre even 64 sub-steps cannot hold the spring the sag needs;
/// World::create refuses a result out of range, naming the field.
[[nodiscard]] WorldDef scale_lengths(WorldDef def, Fixed unit) noexcept;

}  // namespace detsim

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

}  // namespace detsim

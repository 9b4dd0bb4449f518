// Fault injection: a debug aid that changes one field of a World's state at one frame, on this
// machine only — a stand-in for the non-determinism that desync tools must find. `detsim run`,
// `verify` and `netplay` take it as `--inject FRAME:BODY:FIELD:DELTA`; tests use it to prove that
// bisection names exactly the frame, body and field that were changed.
//
// The change is made to the state of frame FRAME: after the step that produces that frame and
// before its hash is taken, so the frame's hash is the first that differs and a field-level diff
// of that frame shows exactly the injected field (a removed body also takes its contacts).
//
// FIELD uses the names state_diff.hpp prints:
//   position.x|y|z  orientation.w|x|y|z  linear_velocity.x|y|z  angular_velocity.x|y|z
//   force.x|y|z  torque.x|y|z  sleep_time                         DELTA: a decimal, added
//   awake                                                         DELTA: 1 toggles the flag
//   user_data                                                     DELTA: an integer, added
//   present               DELTA -1: BODY is removed (its contacts with it, a vehicle it is the
//                         chassis of, characters forget it as ground; nothing is woken);
//                         +1: a static copy of BODY's shape and material is added 1000 m above
//                         it with the next free ID and user_data 0 (not for a plane)
//   rng.state[0..3]       BODY 0; DELTA: an integer, added modulo 2^64
//   contact[OTHER].point[I].normal_impulse|tangent_impulse_1|tangent_impulse_2
//                         the cached impulse of point I of the pair (BODY, OTHER); DELTA: a decimal
//   contact[OTHER/S/T].point[I]....
//                         the same for the contact of BODY's sub-shape S with OTHER's sub-shape T
//                         (a compound's part, a mesh's or heightfield's triangle); contact[OTHER]
//                         is contact[OTHER/0/0]. Diff prints contacts in this form.
//   joint[J].FIELD        BODY 0; FIELD a field of joint J as diff names it (anchor.x,
//                         linear_impulse.y, motor_speed, broken, ...): DELTA as for its kind
//   vehicle[V].FIELD      BODY 0; a field of vehicle V as diff names it (throttle, gear,
//                         engine_rpm, ...); vehicle[V].wheel[K].FIELD of its wheel K's state or
//                         definition (angular_velocity, compression, radius, ...): DELTA as for
//                         its kind
//   character[C].FIELD    BODY 0; FIELD a field of character C as diff names it (position.y,
//                         velocity.x, grounded, ground_body, desired_velocity.z, ...): DELTA as
//                         for its kind
//   particle_group[G].particle[I].position.x|y|z  particle_group[G].particle[I].velocity.x|y|z
//   particle_group[G].force.x|y|z  particle_group[G].sleep_time  particle_group[G].tether_impulse
//                         BODY 0; particle I (0, 1, ...) of particle group G, or the group's own
//                         field; DELTA: a decimal, added
//   particle_group[G].awake
//                         BODY 0; DELTA: 1 toggles the flag
//   game.NAME             BODY 0; a field of the game state (World::describe_game_state names
//                         it): DELTA an integer added at the field's width, a decimal for Fixed
//   game.byte[N]          BODY 0; byte N of the game state; DELTA: an integer, added mod 256
// Results that restore() would refuse (an orientation no longer a unit quaternion, a negative
// sleep time, a static body awake, an all-zero RNG state, a joint's axis no longer a unit vector, a
// character grounded on no body,
// a particle beyond +-2^30 m or m/s) are refused, and the world is unchanged.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include <detsim/core/status.hpp>
#include <detsim/fixed/fixed.hpp>
#include <detsim/sim/world.hpp>

namespace detsim {

struct Injection {
  std::uint64_t frame = 0;  ///< the state frame changed (1 or later: frame 0 is never stepped into)
  std::uint32_t body = 0;   ///< the body; for contact fields either body of the pair; 0 for rng,
                            ///< joint and particle group fields
  std::string field;        ///< as written, e.g. "position.y"
  std::string delta;        ///< as written, e.g. "0.001"

  /// The spec back in FRAME:BODY:FIELD:DELTA form.
  [[nodiscard]] std::string text() const;
};

/// Parses FRAME:BODY:FIELD:DELTA, checking the field's name and the delta's form for that field.
/// Errors name the part that is wrong and what is allowed.
Expected<Injection> parse_injection(std::string_view spec);

/// Applies `injection` to `world` now (callers do it when world.frame() == injection.frame). An
/// unknown body or contact point, or a result restore() would refuse, is an error and the world is
/// unchanged.
Status apply_injection(World& world, const Injection& injection);

/// Applies, in order, every injection whose frame is world.frame(): what a run calls after each
/// step. Stops at the first error.
Status apply_injections(World& world, std::span<const Injection> injections);

/// One line per field form, for --help texts.
[[nodiscard]] std::string_view injection_fields_help() noexcept;

}  // namespace detsim

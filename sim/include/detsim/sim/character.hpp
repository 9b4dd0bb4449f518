// Character controllers: a capsule that walks, climbs steps, keeps to slopes it may walk, slides
// down those it may not, rides moving platforms and pushes dynamic bodies (docs/SIM.md,
// "Characters").
//
// A character is not a rigid body: nothing pushes it but its own input, gravity and the ground it
// stands on, and bodies never see it (it is in no contact, no event, no query). The world moves
// it once per step, after the bodies, with shape casts against them; it is part of the world's
// state (the "characters" section), saved, restored, hashed, diffed and bisected like bodies. Up
// is world +y. Characters have IDs of their own, never reused, assigned in creation order.
#pragma once

#include <compare>
#include <cstdint>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/body.hpp>

namespace detsim {

/// A character's identity: a value, never reused within a world, assigned in creation order (1,
/// 2, 3, ...). Zero is the null ID.
struct CharacterId {
  std::uint32_t value = 0;

  [[nodiscard]] constexpr bool is_null() const noexcept { return value == 0; }
  friend constexpr auto operator<=>(CharacterId, CharacterId) noexcept = default;
};

/// Everything needed to create a character. Plain data with defaults (a person of 1.8 m).
struct CharacterDef {
  Vec3 position{};  ///< the capsule's centre, world space (m)
  /// The capsule (Shape::capsule): its radius and the half length of its straight part, upright
  /// (along world y). The character is 2 (radius + half_height) tall.
  Fixed radius = 0.4_fx;
  Fixed half_height = 0.5_fx;
  /// The steepest ground it stands and walks on (rad, between 0 and pi/2, exclusive): a surface
  /// whose normal is further than this from up is a wall to walk into and a slope to slide down.
  Fixed max_slope = 0.7853981634_fx;  // 45 degrees
  /// The highest ledge it walks up, and the furthest it keeps to the ground when walking down
  /// steps and slopes (m, >= 0, below 2 (radius + half_height)).
  Fixed step_height = 0.3_fx;
  /// kg: how hard it pushes dynamic bodies. It pushes with at most its weight, mass * |gravity|.
  Fixed mass = Fixed::from_int(70);
  /// What it collides with, by QueryFilter's rule: bodies with (body.layer & mask) != 0 and
  /// (layer & body.mask) != 0. Never sensors.
  std::uint32_t layer = 1;
  std::uint32_t mask = 0xFFFFFFFFU;
  std::uint64_t user_data = 0;  ///< the game's own tag, saved and hashed with the character

  friend constexpr bool operator==(const CharacterDef&, const CharacterDef&) noexcept = default;
};

/// What a game sends each frame (World::set_character_input); the next step applies it.
struct CharacterInput {
  /// m/s: where the player wants to walk. Only its horizontal part (x, z) counts. Kept until
  /// changed: a character walks on while the input holds.
  Vec3 desired_velocity{};
  /// m/s upward: a jump, in the next step only (the step clears it); 0 is none. It is applied
  /// whether or not the character stands (the game decides when a jump is allowed, from
  /// CharacterState::grounded).
  Fixed jump{};

  friend constexpr bool operator==(const CharacterInput&, const CharacterInput&) noexcept = default;
};

/// A character's complete state as the world holds it (a copy).
struct CharacterState {
  CharacterId id{};
  CharacterDef def{};  ///< as created (def.position: where it was created)
  Vec3 position{};     ///< the capsule's centre (m)
  /// Its own velocity over the last step (m/s): how far it moved, less how far its ground carried
  /// it, over dt. In the air and on a slope too steep to stand on it carries over to the next step
  /// (with gravity); on walkable ground the input sets it.
  Vec3 velocity{};
  /// Standing on walkable ground (no steeper than max_slope), within the world's linear slop
  /// below its capsule.
  bool grounded = false;
  /// The ground below it (unit, out of the ground) and its body, when it stands (grounded) or
  /// slides down a slope too steep to stand on (not grounded); zero and null in the air.
  Vec3 ground_normal{};
  BodyId ground_body{};
  CharacterInput input{};  ///< what the next step applies

  /// On ground too steep to stand on: it slides down, and its input does not steer it.
  [[nodiscard]] constexpr bool sliding() const noexcept {
    return !grounded && !ground_body.is_null();
  }

  friend constexpr bool operator==(const CharacterState&, const CharacterState&) noexcept = default;
};

}  // namespace detsim

// A ragdoll: eleven bodies (pelvis, chest, head, upper and lower arms, thighs, shins) held by ten
// joints of three types (swing_twist at the spine, shoulders and hips; hinge at the elbows and
// knees; ball at the neck). The `ragdolls` scenario drops several down a flight of stairs; the
// benchmark builds the same figure (from these tables) in detsim and in Bullet.
//
// The tables describe a figure standing upright on y = 0 with its face towards +x and its left
// side towards +z, about 1.7 m tall and 69 kg. add_ragdoll places a copy anywhere, turned by a
// unit quaternion about the point between its feet.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include <detsim/core/status.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/world.hpp>

namespace detsim {

/// One body of the figure: its shape (capsules run along the body's y axis, so limbs hang
/// straight), its centre in the figure's frame, and its mass (kg).
struct RagdollPart {
  std::string_view name;
  Shape shape;
  Vec3 position;
  Fixed mass;
};

/// One joint of the figure: the two parts it joins (indices into ragdoll_parts(), the parent
/// first), its anchor and axis in the figure's frame, and its limits (the JointDef fields of the
/// same names; limit_enabled is set for hinges and swing-twists).
struct RagdollJoint {
  std::string_view name;
  JointType type;
  std::uint8_t parent;
  std::uint8_t child;
  Vec3 anchor;
  Vec3 axis;
  Fixed swing_limit;  ///< swing_twist cone half-angle (radians)
  Fixed limit_lower;  ///< hinge angle or swing_twist twist (radians)
  Fixed limit_upper;
};

inline constexpr std::size_t ragdoll_part_count = 11;
inline constexpr std::size_t ragdoll_joint_count = 10;

/// The figure's bodies, parents before children (the pelvis is part 0).
[[nodiscard]] std::span<const RagdollPart, ragdoll_part_count> ragdoll_parts() noexcept;
/// The figure's joints, in the order add_ragdoll creates them.
[[nodiscard]] std::span<const RagdollJoint, ragdoll_joint_count> ragdoll_joints() noexcept;

/// Where to put a ragdoll and how it starts moving.
struct RagdollPlacement {
  Vec3 position{};                 ///< where the point between its feet goes, world space
  Quat orientation{};              ///< unit quaternion: the figure turned about that point
  Vec3 linear_velocity{};          ///< m/s, every part
  Vec3 angular_velocity{};         ///< rad/s, the whole figure turning about `position`
  Fixed friction = Fixed::half();  ///< every part's
  Fixed angular_damping{};         ///< every part's, 1/s (BodyDef::angular_damping)
  std::uint64_t user_data = 0;     ///< every part's BodyDef::user_data
};

/// The bodies and joints one add_ragdoll made, in table order.
struct Ragdoll {
  std::array<BodyId, ragdoll_part_count> bodies{};
  std::array<JointId, ragdoll_joint_count> joints{};
};

/// Adds one ragdoll to `world`: its bodies in table order (ascending IDs), then its joints. A
/// refusal (a placement beyond the position limit, a non-unit orientation) is returned as the
/// world's message; the bodies already made are then left in the world.
Expected<Ragdoll> add_ragdoll(World& world, const RagdollPlacement& placement);

}  // namespace detsim

// Joints: constraints between two bodies (docs/SIM.md, "Joints": the types, how they behave, and
// what is not done yet).
//
// A joint is created from a JointDef whose anchor and axis are in world space at creation; the
// world keeps them in each body's frame from then on. Joints have IDs of their own, never reused,
// assigned in creation order; everything iterates them in ascending ID order.
#pragma once

#include <compare>
#include <cstdint>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/body.hpp>

namespace detsim {

/// A joint's identity: a value, never reused within a world, assigned in creation order (1, 2,
/// 3, ...). Zero is the null ID.
struct JointId {
  std::uint32_t value = 0;

  [[nodiscard]] constexpr bool is_null() const noexcept { return value == 0; }
  friend constexpr auto operator<=>(JointId, JointId) noexcept = default;
};

/// The numeric values are part of the canonical state encoding (append, never renumber).
enum class JointType : std::uint8_t {
  ball = 0,         ///< the anchors coincide; free rotation
  hinge = 1,        ///< ball, plus rotation about `axis` only
  slider = 2,       ///< translation along `axis` only, no rotation
  fixed = 3,        ///< no relative motion
  distance = 4,     ///< the anchors stay between min_length and max_length apart
  swing_twist = 5,  ///< ball, with a cone limit (swing_limit) and a twist range about `axis`
};

/// Everything needed to create a joint. Plain data with defaults; recordable.
struct JointDef {
  JointType type = JointType::ball;
  /// The two bodies: distinct, existing, at most one of them static.
  BodyId body_a{};
  BodyId body_b{};
  /// World-space point at creation, fixed in both bodies from then on. A distance joint attaches
  /// here to body_a and to body_b's position (its origin: the centre of a primitive).
  Vec3 anchor{};
  /// World-space unit vector at creation (|axis|^2 within 2^-20 of 1): the hinge's and slider's
  /// axis, the swing-twist's twist axis.
  Vec3 axis{Fixed::one(), Fixed::zero(), Fixed::zero()};
  /// Hinge: radians; slider: metres; swing-twist: twist radians. lower <= upper.
  Fixed limit_lower{};
  Fixed limit_upper{};
  bool limit_enabled = false;
  Fixed swing_limit{};  ///< swing-twist cone half-angle, radians, >= 0
  bool motor_enabled = false;
  Fixed motor_speed{};      ///< rad/s (hinge) or m/s (slider), within +-2^30
  Fixed motor_max_force{};  ///< N m (hinge) or N (slider), 0 <= max_force <= 2^31 - 1
  /// Distance joint: metres, 0 <= min_length <= max_length. Both zero: the distance at creation,
  /// held rigidly. A rope is min_length 0, max_length its length (slack below it).
  Fixed min_length{};
  Fixed max_length{};
  Fixed spring_frequency{};      ///< Hz, >= 0; 0 = rigid
  Fixed spring_damping_ratio{};  ///< >= 0
  Fixed break_force{};           ///< N, >= 0; 0 = unbreakable
  Fixed break_torque{};          ///< N m, >= 0; 0 = unbreakable
  bool collide_connected = false;
  std::uint64_t user_data = 0;

  friend constexpr bool operator==(const JointDef&, const JointDef&) noexcept = default;
};

/// A joint's complete state as the world holds it (a copy: it does not follow later changes).
struct JointState {
  JointId id{};
  JointDef def{};         ///< as created (anchor and axis in world space at creation)
  Vec3 local_anchor_a{};  ///< the anchor in body_a's frame (relative to its position)
  Vec3 local_anchor_b{};  ///< in body_b's frame (a distance joint: body_b's position, zero)
  Vec3 local_axis_a{};    ///< the axis in body_a's frame
  Vec3 local_axis_b{};    ///< in body_b's frame
  /// Body b's orientation in body a's frame at creation, conj(q_a) q_b: what a fixed joint holds.
  Quat relative_orientation{};
  Fixed length{};  ///< distance joint: the anchors' distance at creation, m
  /// Accumulated impulses of the last step (warm start), N s per sub-step (the force they carry
  /// is impulse * substeps / dt): the point rows' (world x, y, z).
  Vec3 linear_impulse{};
  Vec3 angular_impulse{};  ///< the angular rows' (hinge, ...) as a world vector, N m s
  Fixed axial_impulse{};   ///< the distance row's, N s (the swing-twist cone's, N m s)
  Fixed motor_impulse{};   ///< the hinge motor's, N m s (the slider motor's, N s)
  /// The hinge's or swing-twist's twist limit (the slider's limit, N s): lower end's minus upper
  /// end's, N m s
  Fixed limit_impulse{};
  /// Broke under break_force or break_torque (at the end of a step): no longer solved, joins no
  /// island, does not keep its bodies from colliding.
  bool broken = false;

  friend constexpr bool operator==(const JointState&, const JointState&) noexcept = default;
};

/// The constraint force and torque a joint applied to body_b (body_a got the opposite): `force`
/// (N, world frame) acts at the joint's anchor on body_b (a distance joint's: body_b's position),
/// `torque` (N m, world frame) is the couple of its angular rows, limits and motors beside that
/// force, so that the joint's moment about its anchor is `torque`. World::joint_reaction derives
/// it from the accumulated impulses the joint keeps, those of the last sub-step of the last step
/// it was solved (impulse * substeps / dt); zero for a broken joint. break_force and break_torque
/// are compared with the mean over the step's sub-steps (docs/SIM.md, "Joints", "Breaking": the
/// last sub-step alone overshoots when a load comes on suddenly).
struct JointReaction {
  Vec3 force{};
  Vec3 torque{};

  friend constexpr bool operator==(const JointReaction&, const JointReaction&) noexcept = default;
};

/// Something that happened to a joint without the game asking for it directly.
struct JointEvent {
  enum class Kind : std::uint8_t {
    broke = 0,      ///< its load passed break_force or break_torque in the step (still readable)
    destroyed = 1,  ///< destroy_body removed one of its bodies, and the joint with it
  };
  Kind kind = Kind::broke;
  JointId joint{};
  BodyId body_a{};
  BodyId body_b{};
  std::uint64_t user_data = 0;  ///< the joint's, since a destroyed joint can no longer be read
  /// For `broke`, the load that broke it (the mean over the step's sub-steps); for `destroyed`,
  /// what joint_reaction() gave just before (zero for a joint destroyed after it broke).
  JointReaction reaction{};

  friend constexpr bool operator==(const JointEvent&, const JointEvent&) noexcept = default;
};

}  // namespace detsim

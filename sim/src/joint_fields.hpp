// A joint's fields, listed once. Internal to detsim::sim.
//
// The "joints" state section's encoder and reader (state_joints.cpp), the field-level diff
// (state_diff.cpp) and fault injection (inject.cpp) walk this one table, so a field added to
// JointState (or JointDef) is added here and every tool sees it: its bytes, its name in a diff,
// its --inject form. What the table does not hold is what identifies a joint: its ID, its type and
// its two bodies (written first in its record).
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include <detsim/sim/joint.hpp>

namespace detsim::sim_detail {

enum class JointFieldKind : std::uint8_t { fixed, vec3, quat, u64, flag };

struct JointField {
  const char* name;  ///< as diff prints it and --inject takes it: "linear_impulse"
  const char* what;  ///< as a reader's error names it: "joint linear impulse"
  JointFieldKind kind;
  /// Encoded only when not zero, its presence a bit of the record's flags (user data). Flags
  /// (JointFieldKind::flag) are bits of the record's flags byte, in table order.
  bool optional = false;
  // The member, by kind (one is set): a function, since half of them are the definition's.
  Fixed& (*fixed)(JointState&) = nullptr;
  Vec3& (*vec3)(JointState&) = nullptr;
  Quat& (*quat)(JointState&) = nullptr;
  std::uint64_t& (*u64)(JointState&) = nullptr;
  bool& (*flag)(JointState&) = nullptr;
};

/// Every field in declaration order (JointDef's, then JointState's own): the order of the bytes
/// and of a diff.
[[nodiscard]] std::span<const JointField> joint_fields() noexcept;

/// The field called `name`, or nullptr.
[[nodiscard]] const JointField* find_joint_field(std::string_view name) noexcept;

/// The record's flags: the flag fields' bits in table order, then the optional fields' presence
/// bits. Every other bit is refused.
inline constexpr unsigned joint_flag_count = 5;

}  // namespace detsim::sim_detail

// A joint's fields, listed once (the mechanism: record_fields.hpp). Internal to detsim::sim.
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

#include "record_fields.hpp"

namespace detsim::sim_detail {

using JointFieldKind = RecordFieldKind;
using JointField = RecordField<JointState>;

/// Every field in declaration order (JointDef's, then JointState's own): the order of the bytes
/// and of a diff.
[[nodiscard]] std::span<const JointField> joint_fields() noexcept;

/// The field called `name`, or nullptr.
[[nodiscard]] const JointField* find_joint_field(std::string_view name) noexcept;

}  // namespace detsim::sim_detail

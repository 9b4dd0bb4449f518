// A body's fields, listed once. Internal to detsim::sim.
//
// The "bodies" state section's encoder and reader (state_bodies.cpp), the field-level diff
// (state_diff.cpp) and fault injection (inject.cpp) all walk this one table, so a field added to
// BodyState is added here and every tool sees it: its bytes, its name in a diff, its --inject
// form. What the table does not hold is what identifies a body rather than describes it: its ID,
// its type and its shape (written first in its property set by the shape's kind, shapes.hpp).
#pragma once

#include <cstdint>
#include <span>

#include <detsim/sim/world.hpp>

namespace detsim::sim_detail {

enum class FieldKind : std::uint8_t { fixed, vec3, quat, u32, u64, flag };

/// Where a field is encoded. Properties are what the simulation never changes by itself (bodies
/// share them in property sets); motion is what a step changes or a game sets each frame.
enum class FieldGroup : std::uint8_t { property, motion };

struct BodyField {
  const char* name;  ///< as diff prints it and --inject takes it: "linear_velocity"
  FieldKind kind;
  FieldGroup group;
  /// Motion only: encoded only when not zero, its presence a bit of the record's flags. Flags
  /// (FieldKind::flag) are bits of the property set's or the record's flags byte.
  bool optional;
  // The member, by kind (one is set).
  Fixed BodyState::*fixed = nullptr;
  Vec3 BodyState::*vec3 = nullptr;
  Quat BodyState::*quat = nullptr;
  std::uint32_t BodyState::*u32 = nullptr;
  std::uint64_t BodyState::*u64 = nullptr;
  bool BodyState::*flag = nullptr;
};

/// Every field in BodyState's declaration order (the order a diff lists them in).
[[nodiscard]] std::span<const BodyField> body_fields() noexcept;

/// The field called `name`, or nullptr.
[[nodiscard]] const BodyField* find_body_field(std::string_view name) noexcept;

/// Whether the field of `b` is zero (all components; false for a flag that is clear).
[[nodiscard]] bool field_is_zero(const BodyField& f, const BodyState& b) noexcept;

/// The two bodies' values of the field are equal.
[[nodiscard]] bool field_equal(const BodyField& f, const BodyState& a, const BodyState& b) noexcept;

/// Sets the field of `b` to zero (false for a flag).
void clear_field(const BodyField& f, BodyState& b) noexcept;

/// Copies the field from `from` to `to`.
void copy_field(const BodyField& f, BodyState& to, const BodyState& from) noexcept;

}  // namespace detsim::sim_detail

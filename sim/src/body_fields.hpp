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

// Per field, per body, on every save: inline, so that the encoder's loops see through them.

/// Whether the field of `b` is zero (all components; a flag: clear).
[[nodiscard]] inline bool field_is_zero(const BodyField& f, const BodyState& b) noexcept {
  switch (f.kind) {
    case FieldKind::fixed:
      return b.*f.fixed == Fixed::zero();
    case FieldKind::vec3:
      return b.*f.vec3 == Vec3{};
    case FieldKind::quat:
      return b.*f.quat == Quat{Fixed::zero(), {}, {}, {}};
    case FieldKind::u32:
      return b.*f.u32 == 0;
    case FieldKind::u64:
      return b.*f.u64 == 0;
    case FieldKind::flag:
      return !(b.*f.flag);
  }
  return false;
}

/// The two bodies' values of the field are equal.
[[nodiscard]] inline bool field_equal(const BodyField& f, const BodyState& a,
                                      const BodyState& b) noexcept {
  switch (f.kind) {
    case FieldKind::fixed:
      return a.*f.fixed == b.*f.fixed;
    case FieldKind::vec3:
      return a.*f.vec3 == b.*f.vec3;
    case FieldKind::quat:
      return a.*f.quat == b.*f.quat;
    case FieldKind::u32:
      return a.*f.u32 == b.*f.u32;
    case FieldKind::u64:
      return a.*f.u64 == b.*f.u64;
    case FieldKind::flag:
      return a.*f.flag == b.*f.flag;
  }
  return false;
}

/// Sets the field of `b` to zero (false for a flag).
inline void clear_field(const BodyField& f, BodyState& b) noexcept {
  switch (f.kind) {
    case FieldKind::fixed:
      b.*f.fixed = {};
      break;
    case FieldKind::vec3:
      b.*f.vec3 = {};
      break;
    case FieldKind::quat:
      b.*f.quat = Quat{Fixed::zero(), {}, {}, {}};
      break;
    case FieldKind::u32:
      b.*f.u32 = 0;
      break;
    case FieldKind::u64:
      b.*f.u64 = 0;
      break;
    case FieldKind::flag:
      b.*f.flag = false;
      break;
  }
}

/// Copies the field from `from` to `to`.
inline void copy_field(const BodyField& f, BodyState& to, const BodyState& from) noexcept {
  switch (f.kind) {
    case FieldKind::fixed:
      to.*f.fixed = from.*f.fixed;
      break;
    case FieldKind::vec3:
      to.*f.vec3 = from.*f.vec3;
      break;
    case FieldKind::quat:
      to.*f.quat = from.*f.quat;
      break;
    case FieldKind::u32:
      to.*f.u32 = from.*f.u32;
      break;
    case FieldKind::u64:
      to.*f.u64 = from.*f.u64;
      break;
    case FieldKind::flag:
      to.*f.flag = from.*f.flag;
      break;
  }
}

}  // namespace detsim::sim_detail

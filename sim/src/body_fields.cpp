// The table of a body's fields (body_fields.hpp).
#include "body_fields.hpp"

#include <array>
#include <string_view>

namespace detsim::sim_detail {

namespace {

// The member pointer's type picks the kind.
constexpr void set_member(BodyField& f, Fixed BodyState::*m) {
  f.kind = FieldKind::fixed;
  f.fixed = m;
}
constexpr void set_member(BodyField& f, Vec3 BodyState::*m) {
  f.kind = FieldKind::vec3;
  f.vec3 = m;
}
constexpr void set_member(BodyField& f, Quat BodyState::*m) {
  f.kind = FieldKind::quat;
  f.quat = m;
}
constexpr void set_member(BodyField& f, std::uint32_t BodyState::*m) {
  f.kind = FieldKind::u32;
  f.u32 = m;
}
constexpr void set_member(BodyField& f, std::uint64_t BodyState::*m) {
  f.kind = FieldKind::u64;
  f.u64 = m;
}
constexpr void set_member(BodyField& f, bool BodyState::*m) {
  f.kind = FieldKind::flag;
  f.flag = m;
}

template <class T>
constexpr BodyField field(const char* name, FieldGroup g, T BodyState::*m, bool optional = false) {
  BodyField f{name, FieldKind::fixed, g, optional};
  set_member(f, m);
  return f;
}

constexpr FieldGroup property = FieldGroup::property;
constexpr FieldGroup motion = FieldGroup::motion;

// BodyState's fields after id, type and shape, in declaration order. The encoding follows from
// the order and the groups (docs/STATE.md, "bodies"): a change of it is a new version of the
// "bodies" section (center_of_mass and inertia_axes came in version 2).
constexpr std::array kFields{
    field("position", motion, &BodyState::position),
    field("orientation", motion, &BodyState::orientation),
    field("linear_velocity", motion, &BodyState::linear_velocity),
    field("angular_velocity", motion, &BodyState::angular_velocity),
    field("mass", property, &BodyState::mass),
    field("inertia", property, &BodyState::inertia),
    field("center_of_mass", property, &BodyState::center_of_mass),
    field("inertia_axes", property, &BodyState::inertia_axes),
    field("friction", property, &BodyState::friction),
    field("restitution", property, &BodyState::restitution),
    field("linear_damping", property, &BodyState::linear_damping),
    field("angular_damping", property, &BodyState::angular_damping),
    field("layer", property, &BodyState::layer),
    field("mask", property, &BodyState::mask),
    field("sensor", property, &BodyState::sensor),
    field("ccd", property, &BodyState::ccd),
    // Bits 2..7 of the property flags (added without a new version: a body without locks
    // encodes as before, and an older reader refuses the bits, naming the ones it knows).
    field("lock_translation_x", property, &BodyState::lock_translation_x),
    field("lock_translation_y", property, &BodyState::lock_translation_y),
    field("lock_translation_z", property, &BodyState::lock_translation_z),
    field("lock_rotation_x", property, &BodyState::lock_rotation_x),
    field("lock_rotation_y", property, &BodyState::lock_rotation_y),
    field("lock_rotation_z", property, &BodyState::lock_rotation_z),
    field("user_data", motion, &BodyState::user_data, true),
    field("awake", motion, &BodyState::awake),
    field("sleep_time", motion, &BodyState::sleep_time),
    field("force", motion, &BodyState::force, true),
    field("torque", motion, &BodyState::torque, true),
};

}  // namespace

std::span<const BodyField> body_fields() noexcept {
  return kFields;
}

const BodyField* find_body_field(std::string_view name) noexcept {
  for (const BodyField& f : kFields) {
    if (name == f.name) return &f;
  }
  return nullptr;
}

}  // namespace detsim::sim_detail

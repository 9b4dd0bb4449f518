// The table of a body's fields (body_fields.hpp).
#include "body_fields.hpp"

#include <array>
#include <string_view>

namespace detsim::sim_detail {

namespace {

constexpr BodyField fixed_field(const char* name, FieldGroup g, Fixed BodyState::*m) {
  BodyField f{name, FieldKind::fixed, g, false};
  f.fixed = m;
  return f;
}
constexpr BodyField vec3_field(const char* name, FieldGroup g, Vec3 BodyState::*m,
                               bool optional = false) {
  BodyField f{name, FieldKind::vec3, g, optional};
  f.vec3 = m;
  return f;
}
constexpr BodyField quat_field(const char* name, FieldGroup g, Quat BodyState::*m) {
  BodyField f{name, FieldKind::quat, g, false};
  f.quat = m;
  return f;
}
constexpr BodyField u32_field(const char* name, FieldGroup g, std::uint32_t BodyState::*m) {
  BodyField f{name, FieldKind::u32, g, false};
  f.u32 = m;
  return f;
}
constexpr BodyField u64_field(const char* name, FieldGroup g, std::uint64_t BodyState::*m,
                              bool optional) {
  BodyField f{name, FieldKind::u64, g, optional};
  f.u64 = m;
  return f;
}
constexpr BodyField flag_field(const char* name, FieldGroup g, bool BodyState::*m) {
  BodyField f{name, FieldKind::flag, g, false};
  f.flag = m;
  return f;
}

constexpr FieldGroup property = FieldGroup::property;
constexpr FieldGroup motion = FieldGroup::motion;

// BodyState's fields after id, type and shape, in declaration order. The encoding follows from
// the order and the groups (docs/STATE.md, "bodies"): never reorder, only append.
constexpr std::array kFields{
    vec3_field("position", motion, &BodyState::position),
    quat_field("orientation", motion, &BodyState::orientation),
    vec3_field("linear_velocity", motion, &BodyState::linear_velocity),
    vec3_field("angular_velocity", motion, &BodyState::angular_velocity),
    fixed_field("mass", property, &BodyState::mass),
    vec3_field("inertia", property, &BodyState::inertia),
    fixed_field("friction", property, &BodyState::friction),
    fixed_field("restitution", property, &BodyState::restitution),
    fixed_field("linear_damping", property, &BodyState::linear_damping),
    fixed_field("angular_damping", property, &BodyState::angular_damping),
    u32_field("layer", property, &BodyState::layer),
    u32_field("mask", property, &BodyState::mask),
    flag_field("sensor", property, &BodyState::sensor),
    flag_field("ccd", property, &BodyState::ccd),
    u64_field("user_data", motion, &BodyState::user_data, true),
    flag_field("awake", motion, &BodyState::awake),
    fixed_field("sleep_time", motion, &BodyState::sleep_time),
    vec3_field("force", motion, &BodyState::force, true),
    vec3_field("torque", motion, &BodyState::torque, true),
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

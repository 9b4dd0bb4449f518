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

bool field_is_zero(const BodyField& f, const BodyState& b) noexcept {
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

bool field_equal(const BodyField& f, const BodyState& a, const BodyState& b) noexcept {
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

void clear_field(const BodyField& f, BodyState& b) noexcept {
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

void copy_field(const BodyField& f, BodyState& to, const BodyState& from) noexcept {
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

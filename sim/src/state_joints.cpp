// The "joints" section of the canonical state (docs/STATE.md): the next joint ID, then one record
// per joint, in ascending ID order, encoded by walking the field table (joint_fields.hpp).
//
// A record is the ID step, the type, the two body IDs, a flags byte (the flag fields in table
// order, then one presence bit per optional field), the values in table order, then the optional
// values that are present. The reader accepts only canonical bytes (the shortest vars, a presence
// bit only for a value that is not zero) and only joints that the solver can take: every check
// create_joint makes except "at most one body static" (set_type may make both static later).
#include <algorithm>
#include <string>

#include <detsim/fixed/decimal.hpp>

#include "joint_fields.hpp"
#include "state_io.hpp"

namespace detsim::sim_detail {

namespace {

#define DETSIM_JOINT_REF(type, member) [](JointState& j) -> type& { return j.member; }

// Every field: the definition's (JointDef's order), then JointState's own (its order).
constexpr JointField kJointFields[] = {
    vec3_field<JointState>("anchor", "joint anchor", DETSIM_JOINT_REF(Vec3, def.anchor)),
    vec3_field<JointState>("axis", "joint axis", DETSIM_JOINT_REF(Vec3, def.axis)),
    fixed_field<JointState>("limit_lower", "joint limit lower",
                            DETSIM_JOINT_REF(Fixed, def.limit_lower)),
    fixed_field<JointState>("limit_upper", "joint limit upper",
                            DETSIM_JOINT_REF(Fixed, def.limit_upper)),
    flag_field<JointState>("limit_enabled", "joint limit enabled",
                           DETSIM_JOINT_REF(bool, def.limit_enabled)),
    fixed_field<JointState>("swing_limit", "joint swing limit",
                            DETSIM_JOINT_REF(Fixed, def.swing_limit)),
    flag_field<JointState>("motor_enabled", "joint motor enabled",
                           DETSIM_JOINT_REF(bool, def.motor_enabled)),
    fixed_field<JointState>("motor_speed", "joint motor speed",
                            DETSIM_JOINT_REF(Fixed, def.motor_speed)),
    fixed_field<JointState>("motor_max_force", "joint motor max force",
                            DETSIM_JOINT_REF(Fixed, def.motor_max_force)),
    fixed_field<JointState>("min_length", "joint min length",
                            DETSIM_JOINT_REF(Fixed, def.min_length)),
    fixed_field<JointState>("max_length", "joint max length",
                            DETSIM_JOINT_REF(Fixed, def.max_length)),
    fixed_field<JointState>("spring_frequency", "joint spring frequency",
                            DETSIM_JOINT_REF(Fixed, def.spring_frequency)),
    fixed_field<JointState>("spring_damping_ratio", "joint spring damping ratio",
                            DETSIM_JOINT_REF(Fixed, def.spring_damping_ratio)),
    fixed_field<JointState>("break_force", "joint break force",
                            DETSIM_JOINT_REF(Fixed, def.break_force)),
    fixed_field<JointState>("break_torque", "joint break torque",
                            DETSIM_JOINT_REF(Fixed, def.break_torque)),
    flag_field<JointState>("collide_connected", "joint collide connected",
                           DETSIM_JOINT_REF(bool, def.collide_connected)),
    u64_field<JointState>("user_data", "joint user data",
                          DETSIM_JOINT_REF(std::uint64_t, def.user_data)),
    vec3_field<JointState>("local_anchor_a", "joint local anchor a",
                           DETSIM_JOINT_REF(Vec3, local_anchor_a)),
    vec3_field<JointState>("local_anchor_b", "joint local anchor b",
                           DETSIM_JOINT_REF(Vec3, local_anchor_b)),
    vec3_field<JointState>("local_axis_a", "joint local axis a",
                           DETSIM_JOINT_REF(Vec3, local_axis_a)),
    vec3_field<JointState>("local_axis_b", "joint local axis b",
                           DETSIM_JOINT_REF(Vec3, local_axis_b)),
    quat_field<JointState>("relative_orientation", "joint relative orientation",
                           DETSIM_JOINT_REF(Quat, relative_orientation)),
    fixed_field<JointState>("length", "joint length", DETSIM_JOINT_REF(Fixed, length)),
    vec3_field<JointState>("linear_impulse", "joint linear impulse",
                           DETSIM_JOINT_REF(Vec3, linear_impulse)),
    vec3_field<JointState>("angular_impulse", "joint angular impulse",
                           DETSIM_JOINT_REF(Vec3, angular_impulse)),
    fixed_field<JointState>("axial_impulse", "joint axial impulse",
                            DETSIM_JOINT_REF(Fixed, axial_impulse)),
    fixed_field<JointState>("motor_impulse", "joint motor impulse",
                            DETSIM_JOINT_REF(Fixed, motor_impulse)),
    fixed_field<JointState>("limit_impulse", "joint limit impulse",
                            DETSIM_JOINT_REF(Fixed, limit_impulse)),
    flag_field<JointState>("broken", "joint broken", DETSIM_JOINT_REF(bool, broken)),
};

#undef DETSIM_JOINT_REF

static_assert(record_flag_count<JointState>(kJointFields) <= 8, "one flags byte");

// The smallest record: ID step, type, two body IDs, flags, then one byte per value component
// (eight vectors, a quaternion, fifteen numbers).
constexpr std::size_t kMinJointBytes = 1 + 1 + 1 + 1 + 1 + 3 * 8 + 4 + 15;

}  // namespace

std::span<const JointField> joint_fields() noexcept {
  return kJointFields;
}

const JointField* find_joint_field(std::string_view name) noexcept {
  return find_record_field<JointState>(kJointFields, name);
}

std::string check_joint_record(const WorldState& s, const JointState& j) {
  if (auto e = check_joint_fields(s, j.def); !e.empty()) return e;
  if (auto e = check_unit_vector("local_axis_a", j.local_axis_a); !e.empty()) return e;
  if (auto e = check_unit_vector("local_axis_b", j.local_axis_b); !e.empty()) return e;
  if (auto e = check_orientation(j.relative_orientation); !e.empty())
    return "relative_orientation: " + e;
  if (j.length < Fixed::zero()) return "length must be >= 0, got " + to_string(j.length);
  return {};
}

void write_joints(const WorldState& s, ByteWriter& w) {
  write_id_records(s.next_joint_id, s.joints, w, [](const JointState& j, ByteWriter& out) {
    out.u8(static_cast<std::uint8_t>(j.def.type));
    out.var(j.def.body_a.value);
    out.var(j.def.body_b.value);
    write_record_fields<JointState>(kJointFields, j, out);
  });
}

bool read_joints(std::span<const std::uint8_t>, ByteReader& r, WorldState& s, std::string& error) {
  return read_id_records(
      r, "joint", 1, kMinJointBytes, s.next_joint_id, s.joints, error,
      [&](JointState& j, std::size_t at) {
        const std::size_t type_at = r.offset();
        const std::uint8_t type = r.u8("joint type");
        if (r.ok() && type > static_cast<std::uint8_t>(JointType::swing_twist))
          r.fail_at(type_at, "joint type",
                    "0-5 (ball, hinge, slider, fixed, distance, swing_twist)");
        j.def.type = static_cast<JointType>(type);
        j.def.body_a = BodyId{r.var32("joint body a")};
        j.def.body_b = BodyId{r.var32("joint body b")};
        if (!r.ok() || !read_record_fields<JointState>(kJointFields, "joint flags", j, r, error))
          return false;
        if (auto e = check_joint_record(s, j); !e.empty()) {
          error = "byte " + std::to_string(at) + ": joint " + std::to_string(j.id.value) + ": " + e;
          return false;
        }
        return true;
      });
}

}  // namespace detsim::sim_detail

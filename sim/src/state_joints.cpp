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

// One constructor per kind; the member is reached through a function, since half of the fields
// are the definition's (no member pointer reaches into JointState::def).
constexpr JointField fixed_field(const char* name, const char* what, Fixed& (*ref)(JointState&)) {
  JointField f{name, what, JointFieldKind::fixed};
  f.fixed = ref;
  return f;
}
constexpr JointField vec3_field(const char* name, const char* what, Vec3& (*ref)(JointState&)) {
  JointField f{name, what, JointFieldKind::vec3};
  f.vec3 = ref;
  return f;
}
constexpr JointField quat_field(const char* name, const char* what, Quat& (*ref)(JointState&)) {
  JointField f{name, what, JointFieldKind::quat};
  f.quat = ref;
  return f;
}
constexpr JointField flag_field(const char* name, const char* what, bool& (*ref)(JointState&)) {
  JointField f{name, what, JointFieldKind::flag};
  f.flag = ref;
  return f;
}
/// An optional 64-bit field: written only when not zero.
constexpr JointField u64_field(const char* name, const char* what,
                               std::uint64_t& (*ref)(JointState&)) {
  JointField f{name, what, JointFieldKind::u64, true};
  f.u64 = ref;
  return f;
}

#define DETSIM_JOINT_REF(type, member) [](JointState& j) -> type& { return j.member; }

// Every field: the definition's (JointDef's order), then JointState's own (its order).
constexpr JointField kJointFields[] = {
    vec3_field("anchor", "joint anchor", DETSIM_JOINT_REF(Vec3, def.anchor)),
    vec3_field("axis", "joint axis", DETSIM_JOINT_REF(Vec3, def.axis)),
    fixed_field("limit_lower", "joint limit lower", DETSIM_JOINT_REF(Fixed, def.limit_lower)),
    fixed_field("limit_upper", "joint limit upper", DETSIM_JOINT_REF(Fixed, def.limit_upper)),
    flag_field("limit_enabled", "joint limit enabled", DETSIM_JOINT_REF(bool, def.limit_enabled)),
    fixed_field("swing_limit", "joint swing limit", DETSIM_JOINT_REF(Fixed, def.swing_limit)),
    flag_field("motor_enabled", "joint motor enabled", DETSIM_JOINT_REF(bool, def.motor_enabled)),
    fixed_field("motor_speed", "joint motor speed", DETSIM_JOINT_REF(Fixed, def.motor_speed)),
    fixed_field("motor_max_force", "joint motor max force",
                DETSIM_JOINT_REF(Fixed, def.motor_max_force)),
    fixed_field("min_length", "joint min length", DETSIM_JOINT_REF(Fixed, def.min_length)),
    fixed_field("max_length", "joint max length", DETSIM_JOINT_REF(Fixed, def.max_length)),
    fixed_field("spring_frequency", "joint spring frequency",
                DETSIM_JOINT_REF(Fixed, def.spring_frequency)),
    fixed_field("spring_damping_ratio", "joint spring damping ratio",
                DETSIM_JOINT_REF(Fixed, def.spring_damping_ratio)),
    fixed_field("break_force", "joint break force", DETSIM_JOINT_REF(Fixed, def.break_force)),
    fixed_field("break_torque", "joint break torque", DETSIM_JOINT_REF(Fixed, def.break_torque)),
    flag_field("collide_connected", "joint collide connected",
               DETSIM_JOINT_REF(bool, def.collide_connected)),
    u64_field("user_data", "joint user data", DETSIM_JOINT_REF(std::uint64_t, def.user_data)),
    vec3_field("local_anchor_a", "joint local anchor a", DETSIM_JOINT_REF(Vec3, local_anchor_a)),
    vec3_field("local_anchor_b", "joint local anchor b", DETSIM_JOINT_REF(Vec3, local_anchor_b)),
    vec3_field("local_axis_a", "joint local axis a", DETSIM_JOINT_REF(Vec3, local_axis_a)),
    vec3_field("local_axis_b", "joint local axis b", DETSIM_JOINT_REF(Vec3, local_axis_b)),
    quat_field("relative_orientation", "joint relative orientation",
               DETSIM_JOINT_REF(Quat, relative_orientation)),
    fixed_field("length", "joint length", DETSIM_JOINT_REF(Fixed, length)),
    vec3_field("linear_impulse", "joint linear impulse", DETSIM_JOINT_REF(Vec3, linear_impulse)),
    vec3_field("angular_impulse", "joint angular impulse", DETSIM_JOINT_REF(Vec3, angular_impulse)),
    fixed_field("axial_impulse", "joint axial impulse", DETSIM_JOINT_REF(Fixed, axial_impulse)),
    fixed_field("motor_impulse", "joint motor impulse", DETSIM_JOINT_REF(Fixed, motor_impulse)),
    fixed_field("limit_impulse", "joint limit impulse", DETSIM_JOINT_REF(Fixed, limit_impulse)),
    flag_field("broken", "joint broken", DETSIM_JOINT_REF(bool, broken)),
};

#undef DETSIM_JOINT_REF

constexpr unsigned count_flags() {
  unsigned n = 0;
  for (const JointField& f : kJointFields)
    n += f.kind == JointFieldKind::flag || f.optional ? 1U : 0U;
  return n;
}
static_assert(count_flags() == joint_flag_count && joint_flag_count <= 8, "one flags byte");

// The smallest record: ID step, type, two body IDs, flags, then one byte per value component
// (eight vectors, a quaternion, fifteen numbers).
constexpr std::size_t kMinJointBytes = 1 + 1 + 1 + 1 + 1 + 3 * 8 + 4 + 15;

// The record's flags byte of `j`.
std::uint8_t joint_flags_of(const JointState& j) {
  auto& m = const_cast<JointState&>(j);  // the accessors take a mutable joint; nothing is written
  unsigned bits = 0;
  unsigned bit = 0;
  for (const JointField& f : kJointFields) {
    if (f.kind == JointFieldKind::flag) bits |= (f.flag(m) ? 1U : 0U) << bit++;
  }
  for (const JointField& f : kJointFields) {
    if (f.optional) bits |= (f.u64(m) != 0 ? 1U : 0U) << bit++;
  }
  return static_cast<std::uint8_t>(bits);
}

const std::string& joint_flags_expected() {
  static const std::string text = [] {
    std::string s = "only bits ";
    unsigned bit = 0;
    for (int pass = 0; pass < 2; ++pass) {
      for (const JointField& f : kJointFields) {
        const bool listed = pass == 0 ? f.kind == JointFieldKind::flag : f.optional;
        if (!listed) continue;
        s += (bit > 0 ? ", " : "") + std::to_string(bit) + " (" + f.name +
             (pass == 1 ? " follows" : "") + ")";
        ++bit;
      }
    }
    return s;
  }();
  return text;
}

void write_joint_value(const JointField& f, JointState& j, ByteWriter& w) {
  switch (f.kind) {
    case JointFieldKind::fixed:
      w.var_fixed(f.fixed(j));
      break;
    case JointFieldKind::vec3:
      w.var_vec3(f.vec3(j));
      break;
    case JointFieldKind::quat:
      w.var_quat(f.quat(j));
      break;
    case JointFieldKind::u64:
      w.var(f.u64(j));
      break;
    case JointFieldKind::flag:
      break;  // a bit of the flags byte
  }
}

void read_joint_value(const JointField& f, JointState& j, ByteReader& r) {
  switch (f.kind) {
    case JointFieldKind::fixed:
      f.fixed(j) = r.var_fixed(f.what);
      break;
    case JointFieldKind::vec3:
      f.vec3(j) = r.var_vec3(f.what);
      break;
    case JointFieldKind::quat:
      f.quat(j) = r.var_quat(f.what);
      break;
    case JointFieldKind::u64:
      f.u64(j) = r.var(f.what);
      break;
    case JointFieldKind::flag:
      break;
  }
}

}  // namespace

std::span<const JointField> joint_fields() noexcept {
  return kJointFields;
}

const JointField* find_joint_field(std::string_view name) noexcept {
  for (const JointField& f : kJointFields) {
    if (name == f.name) return &f;
  }
  return nullptr;
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
  w.u32(s.next_joint_id);
  w.u32(static_cast<std::uint32_t>(s.joints.size()));
  std::uint32_t previous = 0;
  for (const JointState& joint : s.joints) {
    auto& j = const_cast<JointState&>(joint);  // write_joint_value reads through the accessors only
    w.var(j.id.value - previous);
    previous = j.id.value;
    w.u8(static_cast<std::uint8_t>(j.def.type));
    w.var(j.def.body_a.value);
    w.var(j.def.body_b.value);
    w.u8(joint_flags_of(j));
    for (const JointField& f : kJointFields) {
      if (!f.optional) write_joint_value(f, j, w);
    }
    for (const JointField& f : kJointFields) {
      if (f.optional && f.u64(j) != 0) write_joint_value(f, j, w);
    }
  }
}

bool read_joints(std::span<const std::uint8_t>, ByteReader& r, WorldState& s, std::string& error) {
  const auto failed_at = [&](std::size_t at, const std::string& message) {
    error = "byte " + std::to_string(at) + ": " + message;
    return false;
  };
  const std::size_t next_at = r.offset();
  s.next_joint_id = r.u32("next joint id");
  if (r.ok() && s.next_joint_id == 0) return failed_at(next_at, "next joint ID must be >= 1");
  const std::size_t count_at = r.offset();
  const std::uint32_t count = r.u32("joint count");
  if (r.ok() && count > r.remaining() / kMinJointBytes)
    return failed_at(count_at,
                     "joint count " + std::to_string(count) + " exceeds what the data can hold");
  s.joints.clear();
  s.joints.reserve(count);
  std::uint32_t previous = 0;
  for (std::uint32_t i = 0; i < count && r.ok(); ++i) {
    const std::size_t at = r.offset();
    JointState j;
    const std::uint32_t step = r.var32("joint ID step");
    if (r.ok() && (step == 0 || step > s.next_joint_id - 1 - previous))
      return failed_at(at, "joint ID step " + std::to_string(step) + " after ID " +
                               std::to_string(previous) + ": IDs must ascend and stay below the " +
                               "next joint ID " + std::to_string(s.next_joint_id));
    j.id = JointId{previous + step};
    previous = j.id.value;
    const std::size_t type_at = r.offset();
    const std::uint8_t type = r.u8("joint type");
    if (r.ok() && type > static_cast<std::uint8_t>(JointType::swing_twist))
      r.fail_at(type_at, "joint type", "0-5 (ball, hinge, slider, fixed, distance, swing_twist)");
    j.def.type = static_cast<JointType>(type);
    j.def.body_a = BodyId{r.var32("joint body a")};
    j.def.body_b = BodyId{r.var32("joint body b")};
    const std::size_t flags_at = r.offset();
    const std::uint8_t flags = r.u8("joint flags");
    if (r.ok() && (flags >> joint_flag_count) != 0)
      r.fail_at(flags_at, "joint flags", joint_flags_expected().c_str());
    if (!r.ok()) break;
    unsigned bit = 0;
    for (const JointField& f : kJointFields) {
      if (f.kind == JointFieldKind::flag) f.flag(j) = ((flags >> bit++) & 1U) != 0;
    }
    for (const JointField& f : kJointFields) {
      if (!f.optional) read_joint_value(f, j, r);
    }
    for (const JointField& f : kJointFields) {
      if (!f.optional || ((flags >> bit++) & 1U) == 0) continue;
      const std::size_t value_at = r.offset();
      read_joint_value(f, j, r);
      if (r.ok() && f.u64(j) == 0)
        return failed_at(value_at, std::string(f.what) + " flagged present but zero");
    }
    if (!r.ok()) break;
    if (auto e = check_joint_record(s, j); !e.empty())
      return failed_at(at, "joint " + std::to_string(j.id.value) + ": " + e);
    s.joints.push_back(j);
  }
  return r.ok();
}

}  // namespace detsim::sim_detail

// The "bodies" section of the canonical state (docs/STATE.md): property sets, then one record per
// body, both encoded by walking the field table (body_fields.hpp).
//
// A body's properties (type, shape, then the property fields in table order, their flags in one
// byte) are what the simulation never changes by itself; bodies share them in property sets,
// listed in order of first use. A record is the ID step, the set, a flags byte (the motion flags
// in table order, then one presence bit per optional field in table order), the motion values in
// table order, then the optional values that are present. The reader accepts only canonical bytes:
// the shortest vars, sets in first-use order and unique, a presence bit only for a value that is
// not zero.
#include <algorithm>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

#include <detsim/core/assert.hpp>
#include <detsim/fixed/decimal.hpp>

#include "body_fields.hpp"
#include "limits.hpp"
#include "shapes.hpp"
#include "state_io.hpp"

namespace detsim::sim_detail {

namespace {

// Smallest encodings, to bound counts by the bytes that remain before allocating.
constexpr std::size_t kMinPropertyBytes = 1 + 1 + 1 + 3 + 4 + 4 + 4 + 1;
constexpr std::size_t kMinBodyBytes = 1 + 1 + 1 + 3 + 4 + 3 + 3 + 1;

/// The table's fields of one group in their encoded roles, worked out once: the flags (their bit
/// is their index here), the values, and the optional values (motion: presence bit = flag count +
/// index here).
struct GroupLayout {
  std::vector<const BodyField*> flags;
  std::vector<const BodyField*> values;
  std::vector<const BodyField*> optional;
  std::vector<std::string> names;  // "body linear velocity": ByteReader keeps the pointers
  std::string flags_expected;      // "only bits 0 (awake), 1 (user data), ..."

  explicit GroupLayout(FieldGroup group) {
    for (const BodyField& f : body_fields()) {
      if (f.group != group) continue;
      if (f.kind == FieldKind::flag) {
        flags.push_back(&f);
      } else if (f.optional) {
        optional.push_back(&f);
      } else {
        values.push_back(&f);
      }
    }
    DETSIM_ASSERT(flags.size() + optional.size() <= 8);  // one flags byte
    names.reserve(body_fields().size());
    for (const BodyField& f : body_fields())
      names.push_back("body " + display(f));
    flags_expected = "only bits ";
    std::size_t bit = 0;
    for (const auto* list : {&flags, &optional}) {
      for (const BodyField* f : *list) {
        if (bit > 0) flags_expected += ", ";
        flags_expected += std::to_string(bit++) + " (" + display(*f) + ")";
      }
    }
  }
  [[nodiscard]] std::uint8_t all_bits() const {
    return static_cast<std::uint8_t>((1U << (flags.size() + optional.size())) - 1U);
  }
  [[nodiscard]] const char* name(const BodyField& f) const {
    return names[static_cast<std::size_t>(&f - body_fields().data())].c_str();
  }
  [[nodiscard]] static std::string display(const BodyField& f) {
    std::string s = f.name;
    for (char& c : s)
      if (c == '_') c = ' ';
    return s == "ccd" ? "CCD" : s;
  }
};

const GroupLayout& properties_layout() {
  static const GroupLayout layout(FieldGroup::property);
  return layout;
}
const GroupLayout& motion_layout() {
  static const GroupLayout layout(FieldGroup::motion);
  return layout;
}

[[gnu::always_inline]] inline void write_value(const BodyField& f, const BodyState& b,
                                               ByteWriter& w) {
  switch (f.kind) {
    case FieldKind::fixed:
      w.var_fixed(b.*f.fixed);
      break;
    case FieldKind::vec3:
      w.var_vec3(b.*f.vec3);
      break;
    case FieldKind::quat:
      w.var_quat(b.*f.quat);
      break;
    case FieldKind::u32:
      w.u32(b.*f.u32);
      break;
    case FieldKind::u64:
      w.var(b.*f.u64);
      break;
    case FieldKind::flag:
      break;  // a bit of the flags byte
  }
}

void read_value(const BodyField& f, BodyState& b, ByteReader& r, const char* what) {
  switch (f.kind) {
    case FieldKind::fixed:
      b.*f.fixed = r.var_fixed(what);
      break;
    case FieldKind::vec3:
      b.*f.vec3 = r.var_vec3(what);
      break;
    case FieldKind::quat:
      b.*f.quat = r.var_quat(what);
      break;
    case FieldKind::u32:
      b.*f.u32 = r.u32(what);
      break;
    case FieldKind::u64:
      b.*f.u64 = r.var(what);
      break;
    case FieldKind::flag:
      break;
  }
}

[[gnu::always_inline]] inline std::uint8_t flags_of(const GroupLayout& layout, const BodyState& b) {
  unsigned bits = 0;
  unsigned bit = 0;
  for (const BodyField* f : layout.flags)
    bits |= (b.*f->flag ? 1U : 0U) << bit++;
  for (const BodyField* f : layout.optional)
    bits |= (field_is_zero(*f, b) ? 0U : 1U) << bit++;
  return static_cast<std::uint8_t>(bits);
}

// ---- Property sets: what a body has that the simulation never changes by itself ----

/// The property part of a body: type, shape and the property fields. Two bodies share a set
/// exactly when their sets' bytes would be equal.
bool same_properties(const BodyState& a, const BodyState& b) noexcept {
  if (a.type != b.type || !(a.shape == b.shape)) return false;
  for (const BodyField* f : properties_layout().values)
    if (!field_equal(*f, a, b)) return false;
  for (const BodyField* f : properties_layout().flags)
    if (!field_equal(*f, a, b)) return false;
  return true;
}

void copy_properties(BodyState& to, const BodyState& from) noexcept {
  to.type = from.type;
  to.shape = from.shape;
  for (const BodyField& f : body_fields()) {
    if (f.group == FieldGroup::property) copy_field(f, to, from);
  }
}

void write_properties(const BodyState& b, ByteWriter& w) {
  const GroupLayout& layout = properties_layout();
  w.u8(static_cast<std::uint8_t>(b.type));
  w.u8(static_cast<std::uint8_t>(b.shape.type));
  shape_kind(b.shape.type).write(b.shape, w);
  for (const BodyField* f : layout.values)
    write_value(*f, b, w);
  w.u8(flags_of(layout, b));
}

// A shape: its type, then the fields its kind reads.
Shape read_shape(ByteReader& r) {
  const std::size_t type_at = r.offset();
  const std::uint8_t type = r.u8("shape type");
  if (const ShapeKind* kind = find_shape_kind(static_cast<ShapeType>(type))) return kind->read(r);
  // The reader keeps the pointer: "1 (sphere), 2 (box), 3 (capsule) or 4 (plane)", built once.
  static const std::string expected = [] {
    std::string list;
    const auto kinds = shape_kinds();
    for (std::size_t i = 0; i < kinds.size(); ++i) {
      if (i > 0) list += i + 1 == kinds.size() ? " or " : ", ";
      list += std::to_string(static_cast<unsigned>(kinds[i]->type)) + " (" + kinds[i]->name + ")";
    }
    return list;
  }();
  r.fail_at(type_at, "shape type", expected.c_str());
  return {};
}

/// Reads a property set into the property part of `b`.
void read_properties(ByteReader& r, BodyState& b) {
  const GroupLayout& layout = properties_layout();
  const std::size_t type_at = r.offset();
  const std::uint8_t type = r.u8("body type");
  if (type > static_cast<std::uint8_t>(BodyType::dynamic))
    r.fail_at(type_at, "body type", "0 (static), 1 (kinematic) or 2 (dynamic)");
  b.type = static_cast<BodyType>(type);
  b.shape = read_shape(r);
  for (const BodyField* f : layout.values)
    read_value(*f, b, r, layout.name(*f));
  const std::size_t flags_at = r.offset();
  const std::uint8_t flags = r.u8("property flags");
  if ((flags & ~layout.all_bits()) != 0)
    r.fail_at(flags_at, "property flags", layout.flags_expected.c_str());
  for (std::size_t bit = 0; bit < layout.flags.size(); ++bit)
    b.*layout.flags[bit]->flag = ((flags >> bit) & 1U) != 0;
}

// Semantic checks of a property set read from bytes; "" when valid. The limits are the API's
// (limits.hpp, docs/SIM.md "What is refused") for what a step never changes: a restored world
// holds nothing that create_body would have refused.
std::string check_properties(const GeometryTable& geometries, const BodyState& p) {
  if (auto e = check_shape(geometries, p.shape, p.type); !e.empty()) return e;
  if (p.mass < Fixed::zero()) return "mass must be >= 0";
  if (p.type == BodyType::dynamic && (p.mass <= Fixed::zero() || p.inertia.x <= Fixed::zero() ||
                                      p.inertia.y <= Fixed::zero() || p.inertia.z <= Fixed::zero()))
    return "a dynamic body needs a positive mass and moments of inertia";
  if (p.mass > max_quantity || p.inertia.x > max_quantity || p.inertia.y > max_quantity ||
      p.inertia.z > max_quantity)
    return "mass and moments of inertia must be <= " + to_string(max_quantity) + ", got " +
           to_string(p.mass) + " kg and " + to_string(p.inertia.x) + ", " + to_string(p.inertia.y) +
           ", " + to_string(p.inertia.z) + " kg m^2";
  if (p.type == BodyType::dynamic && (p.mass < min_mass || p.inertia.x < min_mass ||
                                      p.inertia.y < min_mass || p.inertia.z < min_mass))
    return "a dynamic body's mass and moments of inertia must be >= " + to_string(min_mass) +
           " (their inverses must fit)";
  if (p.friction < Fixed::zero() || p.restitution < Fixed::zero() || p.restitution > Fixed::one() ||
      p.linear_damping < Fixed::zero() || p.angular_damping < Fixed::zero())
    return "material or damping out of range";
  // The centre of mass lies in the shape (sizes are at most 10^4 m), and the principal axes are a
  // rotation, as mass_properties makes them.
  if (beyond(p.center_of_mass.x, max_shape_size) || beyond(p.center_of_mass.y, max_shape_size) ||
      beyond(p.center_of_mass.z, max_shape_size))
    return "centre of mass components must be within +-" + to_string(max_shape_size) + " m";
  if (auto e = check_orientation(p.inertia_axes); !e.empty()) return "inertia axes: " + e;
  return {};
}

// ---- Records: the ID step, the property set, then what moves ----

void write_record(const BodyState& b, std::uint32_t previous_id, std::uint32_t set, ByteWriter& w) {
  const GroupLayout& layout = motion_layout();
  w.var(b.id.value - previous_id);
  w.var(set);
  const std::uint8_t flags = flags_of(layout, b);
  w.u8(flags);
  for (const BodyField* f : layout.values)
    write_value(*f, b, w);
  for (std::size_t i = 0; i < layout.optional.size(); ++i) {
    if (((flags >> (layout.flags.size() + i)) & 1U) != 0) write_value(*layout.optional[i], b, w);
  }
}

/// Reads a body record into `b` (not its property fields); `id_step` and `set` are returned for
/// the caller to check against the bodies and sets before it.
void read_record(ByteReader& r, BodyState& b, std::uint32_t& id_step, std::uint32_t& set) {
  const GroupLayout& layout = motion_layout();
  id_step = r.var32("body id step");
  set = r.var32("body property set");
  const std::size_t flags_at = r.offset();
  const std::uint8_t flags = r.u8("body flags");
  if ((flags & ~layout.all_bits()) != 0)
    r.fail_at(flags_at, "body flags", layout.flags_expected.c_str());
  for (std::size_t bit = 0; bit < layout.flags.size(); ++bit)
    b.*layout.flags[bit]->flag = ((flags >> bit) & 1U) != 0;
  for (const BodyField* f : layout.values)
    read_value(*f, b, r, layout.name(*f));
  for (std::size_t i = 0; i < layout.optional.size(); ++i) {
    const BodyField& f = *layout.optional[i];
    const bool present = ((flags >> (layout.flags.size() + i)) & 1U) != 0;
    // Absent is zero; a value flagged present must not be zero (zero is written by leaving the
    // flag clear), so that every state has one encoding.
    clear_field(f, b);
    if (!present) continue;
    read_value(f, b, r, layout.name(f));
    if (r.ok() && field_is_zero(f, b))
      r.fail_at(flags_at, layout.name(f), "a value that is not zero when its flag is set");
  }
}

// Semantic checks of a body's moving part; "" when valid.
std::string check_record(const BodyState& b) {
  if (auto e = check_orientation(b.orientation); !e.empty()) return e;
  // Velocities: what the API accepts (a step only clamps them lower). Positions are not limited
  // here: a body may travel past max_position by stepping, and what was saved must restore.
  for (const Vec3 v : {b.linear_velocity, b.angular_velocity}) {
    if (beyond(v.x, max_velocity) || beyond(v.y, max_velocity) || beyond(v.z, max_velocity))
      return "velocity components must be within +-" + to_string(max_velocity) + ", got (" +
             to_string(v.x) + ", " + to_string(v.y) + ", " + to_string(v.z) + ")";
  }
  if (b.sleep_time < Fixed::zero()) return "sleep time must be >= 0";
  if (b.type == BodyType::static_body && b.awake) return "a static body cannot be awake";
  return {};
}

}  // namespace

std::string check_body_record(const BodyState& b) {
  return check_record(b);
}

void write_body(const BodyState& b, ByteWriter& w) {
  write_properties(b, w);
  write_record(b, 0, 0, w);
}

// The property sets, in order of first use, then the bodies. A body usually shares its set with
// the body before it (scenes create alike bodies together), which is compared field by field;
// otherwise its set's bytes are looked up among the sets written so far.
void write_bodies(const WorldState& s, ByteWriter& w) {
  ByteWriter sets;
  std::uint32_t set_count = 0;
  std::unordered_map<std::string, std::uint32_t> index_of;
  std::vector<std::uint32_t> set_of(s.bodies.size());
  ByteWriter key;
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    if (i > 0 && same_properties(s.bodies[i], s.bodies[i - 1])) {
      set_of[i] = set_of[i - 1];
      continue;
    }
    key.clear();
    write_properties(s.bodies[i], key);
    const auto [it, added] =
        index_of.try_emplace(std::string(key.bytes().begin(), key.bytes().end()), set_count);
    if (added) {
      sets.raw(key.bytes());
      ++set_count;
    }
    set_of[i] = it->second;
  }
  w.u32(set_count);
  w.raw(sets.bytes());
  w.u32(static_cast<std::uint32_t>(s.bodies.size()));
  std::uint32_t previous_id = 0;
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    write_record(s.bodies[i], previous_id, set_of[i], w);
    previous_id = s.bodies[i].id.value;
  }
}

bool read_bodies(std::span<const std::uint8_t> bytes, ByteReader& r, WorldState& s,
                 std::string& error) {
  const auto failed_at = [&](std::size_t at, const std::string& message) {
    error = "byte " + std::to_string(at) + ": " + message;
    return false;
  };
  const std::size_t set_count_at = r.offset();
  const std::uint32_t set_count = r.u32("property set count");
  if (r.ok() && set_count > r.remaining() / kMinPropertyBytes)
    return failed_at(set_count_at, "property set count " + std::to_string(set_count) +
                                       " exceeds what the data can hold");
  // Each set's bytes must differ from every other's.
  std::vector<BodyState> sets;
  sets.reserve(set_count);
  std::unordered_set<std::string_view> seen;
  for (std::uint32_t i = 0; i < set_count && r.ok(); ++i) {
    const std::size_t at = r.offset();
    BodyState p;
    read_properties(r, p);
    if (!r.ok()) break;
    const std::string where = "property set " + std::to_string(i) + ": ";
    if (auto e = check_properties(s.geometries, p); !e.empty()) return failed_at(at, where + e);
    const std::string_view set_bytes(reinterpret_cast<const char*>(bytes.data() + at),
                                     r.offset() - at);
    if (!seen.insert(set_bytes).second) return failed_at(at, where + "the same as an earlier set");
    sets.push_back(p);
  }
  if (!r.ok()) return false;

  const std::size_t body_count_at = r.offset();
  const std::uint32_t body_count = r.u32("body count");
  if (r.ok() && body_count > r.remaining() / kMinBodyBytes)
    return failed_at(body_count_at, "body count " + std::to_string(body_count) +
                                        " exceeds what the data can hold");
  s.bodies.clear();
  s.bodies.reserve(body_count);
  std::uint32_t sets_used = 0;  // sets are numbered in order of first use
  std::uint32_t previous_id = 0;
  for (std::uint32_t i = 0; i < body_count && r.ok(); ++i) {
    const std::size_t at = r.offset();
    BodyState b;
    std::uint32_t id_step = 0;
    std::uint32_t set = 0;
    read_record(r, b, id_step, set);
    if (!r.ok()) break;
    const std::uint64_t id = std::uint64_t{previous_id} + id_step;
    const std::string where = "body " + std::to_string(id) + ": ";
    if (id_step == 0) return failed_at(at, where + "IDs must be unique and ascending");
    if (id >= s.next_id)
      return failed_at(at, where + "ID must be in 1.." + std::to_string(s.next_id - 1));
    if (set > sets_used || set >= set_count)
      return failed_at(at,
                       where + "property set " + std::to_string(set) +
                           (set >= set_count ? " does not exist"
                                             : " is used before set " + std::to_string(sets_used) +
                                                   " (sets are listed in order of first use)"));
    if (set == sets_used) ++sets_used;
    b.id = BodyId{static_cast<std::uint32_t>(id)};
    copy_properties(b, sets[set]);
    if (auto e = check_record(b); !e.empty()) return failed_at(at, where + e);
    s.bodies.push_back(b);
    previous_id = b.id.value;
  }
  if (!r.ok()) return false;
  if (sets_used != set_count)
    return failed_at(set_count_at,
                     "property set " + std::to_string(sets_used) + " is used by no body");
  return true;
}

// ---- Delta coding (state_delta.cpp) ----

namespace {

void shift_field(const BodyField& f, BodyState& b, const BodyState& by, bool add) noexcept {
  switch (f.kind) {
    case FieldKind::fixed:
      b.*f.fixed = shifted_value(b.*f.fixed, by.*f.fixed, add);
      break;
    case FieldKind::vec3: {
      Vec3& v = b.*f.vec3;
      const Vec3 d = by.*f.vec3;
      v = {shifted_value(v.x, d.x, add), shifted_value(v.y, d.y, add),
           shifted_value(v.z, d.z, add)};
      break;
    }
    case FieldKind::quat: {
      Quat& q = b.*f.quat;
      const Quat d = by.*f.quat;
      q = {shifted_value(q.w, d.w, add), shifted_value(q.x, d.x, add), shifted_value(q.y, d.y, add),
           shifted_value(q.z, d.z, add)};
      break;
    }
    case FieldKind::u32:
      b.*f.u32 = add ? b.*f.u32 + by.*f.u32 : b.*f.u32 - by.*f.u32;
      break;
    case FieldKind::u64:
      b.*f.u64 = add ? b.*f.u64 + by.*f.u64 : b.*f.u64 - by.*f.u64;
      break;
    case FieldKind::flag:
      break;  // flags are sent as they are
  }
}

/// A "bodies" payload read without its semantic checks: the property sets as they are written
/// (their count first), and every record's motion, ID and set.
struct BodyRecords {
  std::span<const std::uint8_t> sets;
  std::vector<BodyState> bodies;
  std::vector<std::uint32_t> set_of;
};

bool read_body_records(std::span<const std::uint8_t> bytes, const StateSection& section,
                       BodyRecords& out, std::string& error) {
  ByteReader r(bytes.first(section.payload_offset + section.payload.size()),
               section.payload_offset);
  const std::uint32_t set_count = r.u32("property set count");
  if (r.ok() && set_count > r.remaining() / kMinPropertyBytes)
    r.fail_at(section.payload_offset, "property set count", "what the data can hold");
  for (std::uint32_t i = 0; i < set_count && r.ok(); ++i) {
    BodyState p;
    read_properties(r, p);
  }
  out.sets = bytes.subspan(section.payload_offset, r.offset() - section.payload_offset);
  const std::size_t body_count_at = r.offset();
  const std::uint32_t body_count = r.u32("body count");
  if (r.ok() && body_count > r.remaining() / kMinBodyBytes)
    r.fail_at(body_count_at, "body count", "what the data can hold");
  if (r.ok()) {
    out.bodies.reserve(body_count);
    out.set_of.reserve(body_count);
  }
  std::uint32_t previous_id = 0;
  for (std::uint32_t i = 0; i < body_count && r.ok(); ++i) {
    const std::size_t at = r.offset();
    BodyState b;
    std::uint32_t id_step = 0;
    std::uint32_t set = 0;
    read_record(r, b, id_step, set);
    if (r.ok() && (id_step == 0 || id_step > 0xFFFFFFFFU - previous_id))
      r.fail_at(at, "body id step", "IDs unique, ascending and below 2^32");
    previous_id += id_step;
    b.id = BodyId{previous_id};
    out.bodies.push_back(b);
    out.set_of.push_back(set);
  }
  if (r.ok() && !r.at_end())
    r.fail_at(r.offset(), "bodies", "the section's end after the last body");
  if (!r.ok()) error = r.error();
  return r.ok();
}

/// Shifts `b`'s motion by its prediction from `base` (the same body `ahead` seconds before):
/// velocities and every other field as they were; the sleep timer counting on while it runs; the
/// pose carried on at the mean of the base's velocities and b's (the trapezoid rule, which a step's
/// integration follows closely). So the pose is shifted after the velocities, whose values (b's
/// before a shift that takes them away, after one that gives them back) it needs.
void shift_motion(const GroupLayout& layout, BodyState& b, const BodyState& base, Fixed ahead,
                  bool add) {
  const auto pose = [](const BodyField& f) {
    return f.vec3 == &BodyState::position || f.quat == &BodyState::orientation;
  };
  Vec3 linear = b.linear_velocity;  // b's own, while b holds them
  Vec3 angular = b.angular_velocity;
  BodyState by = base;
  if (base.awake && base.sleep_time > Fixed::zero())
    by.sleep_time = min(base.sleep_time + ahead, Fixed::from_int(1000));
  for (const std::vector<const BodyField*>* list : {&layout.values, &layout.optional})
    for (const BodyField* f : *list)
      if (!pose(*f)) shift_field(*f, b, by, add);
  if (add) {
    linear = b.linear_velocity;
    angular = b.angular_velocity;
  }
  const Fixed half = ahead >> 1;
  by.position = base.position + (base.linear_velocity + linear) * half;
  by.orientation =
      integrate(base.orientation,
                (base.angular_velocity + angular) * Fixed::from_raw(std::int64_t{1} << 31), ahead);
  for (const BodyField* f : layout.values)
    if (pose(*f)) shift_field(*f, b, by, add);
}

}  // namespace

bool shift_bodies(std::span<const std::uint8_t> bytes, const StateSection& section,
                  std::span<const std::uint8_t> base_bytes, const StateSection& base, Fixed ahead,
                  bool add, ByteWriter& out, std::string& error) {
  BodyRecords in;
  BodyRecords from;
  if (!read_body_records(bytes, section, in, error)) return false;
  if (!read_body_records(base_bytes, base, from, error)) {
    error = "base: " + error;
    return false;
  }
  const GroupLayout& layout = motion_layout();
  out.raw(in.sets);
  out.u32(static_cast<std::uint32_t>(in.bodies.size()));
  std::uint32_t previous_id = 0;
  for (std::size_t i = 0; i < in.bodies.size(); ++i) {
    BodyState& b = in.bodies[i];
    const auto it =
        std::lower_bound(from.bodies.begin(), from.bodies.end(), b.id.value,
                         [](const BodyState& x, std::uint32_t id) { return x.id.value < id; });
    if (it != from.bodies.end() && it->id == b.id) shift_motion(layout, b, *it, ahead, add);
    write_record(b, previous_id, in.set_of[i], out);
    previous_id = b.id.value;
  }
  return true;
}

}  // namespace detsim::sim_detail

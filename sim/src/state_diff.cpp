// Field-level state comparison (state_diff.hpp). Both states are restored into scratch worlds
// (so both are fully validated); each section whose hash differs is compared by its differ
// (kDiffers): bodies field by field through the field table (body_fields.hpp), contacts pair by
// pair (World::contacts()), point by point, joints and characters field by field through their
// tables (joint_fields.hpp, character_fields.hpp). A section without a differ is named by its
// hashes.
#include <detsim/sim/state_diff.hpp>

#include <algorithm>
#include <array>
#include <cstdio>

#include <detsim/core/bytes.hpp>
#include <detsim/core/hash.hpp>
#include <detsim/fixed/decimal.hpp>
#include <detsim/sim/state_sections.hpp>

#include "body_fields.hpp"
#include "character_fields.hpp"
#include "geometry/geometry.hpp"
#include "joint_fields.hpp"
#include "vehicle_fields.hpp"
#include "world_state.hpp"

namespace detsim {
namespace {

std::string hex(std::uint64_t v) {
  char text[19];
  std::snprintf(text, sizeof text, "0x%016llx", static_cast<unsigned long long>(v));
  return text;
}

std::string show(Fixed v) {
  return to_string(v) + " (" + hex(static_cast<std::uint64_t>(v.raw())) + ")";
}
std::string show(std::uint64_t v) {
  return std::to_string(v) + " (" + hex(v) + ")";
}
std::string show(bool v) {
  return v ? "true" : "false";
}
std::string show(JointType t) {
  switch (t) {
    case JointType::ball:
      return "ball";
    case JointType::hinge:
      return "hinge";
    case JointType::slider:
      return "slider";
    case JointType::fixed:
      return "fixed";
    case JointType::distance:
      return "distance";
    case JointType::swing_twist:
      return "swing_twist";
  }
  return "unknown";
}
std::string show(ParticleGroupType t) {
  switch (t) {
    case ParticleGroupType::rope:
      return "rope";
    case ParticleGroupType::cloth:
      return "cloth";
    case ParticleGroupType::soft_body:
      return "soft_body";
    case ParticleGroupType::fluid:
      return "fluid";
  }
  return "unknown";
}
std::string show(BodyType t) {
  switch (t) {
    case BodyType::static_body:
      return "static";
    case BodyType::kinematic:
      return "kinematic";
    case BodyType::dynamic:
      return "dynamic";
  }
  return "unknown";
}

class Collector {
 public:
  Collector(StateDiff& out, std::size_t max) : out_(out), max_(max) {}

  void add(const char* subsystem, std::uint32_t body, std::string field, std::string a,
           std::string b) {
    if (out_.fields.size() >= max_) {
      ++out_.omitted;
      return;
    }
    out_.fields.push_back(FieldDiff{subsystem, body, std::move(field), std::move(a), std::move(b)});
  }
  template <class T>
  void field(std::uint32_t body, const std::string& name, const T& a, const T& b,
             const char* subsystem = "bodies") {
    if (!(a == b)) add(subsystem, body, name, show(a), show(b));
  }
  void vec(std::uint32_t body, const std::string& name, Vec3 a, Vec3 b,
           const char* subsystem = "bodies") {
    field(body, name + ".x", a.x, b.x, subsystem);
    field(body, name + ".y", a.y, b.y, subsystem);
    field(body, name + ".z", a.z, b.z, subsystem);
  }
  void quat(std::uint32_t body, const std::string& name, Quat a, Quat b,
            const char* subsystem = "bodies") {
    field(body, name + ".w", a.w, b.w, subsystem);
    field(body, name + ".x", a.x, b.x, subsystem);
    field(body, name + ".y", a.y, b.y, subsystem);
    field(body, name + ".z", a.z, b.z, subsystem);
  }

 private:
  StateDiff& out_;
  std::size_t max_;
};

// Every field of the table (body_fields.hpp), in its order: a new field is diffed by being listed.
void diff_body(Collector& c, const BodyState& a, const BodyState& b) {
  const std::uint32_t id = a.id.value;
  if (a.type != b.type) c.add("bodies", id, "type", show(a.type), show(b.type));
  if (!(a.shape == b.shape)) c.add("bodies", id, "shape", "(differs)", "(differs)");
  for (const sim_detail::BodyField& f : sim_detail::body_fields()) {
    switch (f.kind) {
      case sim_detail::FieldKind::fixed:
        c.field(id, f.name, a.*f.fixed, b.*f.fixed);
        break;
      case sim_detail::FieldKind::vec3:
        c.vec(id, f.name, a.*f.vec3, b.*f.vec3);
        break;
      case sim_detail::FieldKind::quat:
        c.quat(id, f.name, a.*f.quat, b.*f.quat);
        break;
      case sim_detail::FieldKind::u32:
        c.field(id, f.name, std::uint64_t{a.*f.u32}, std::uint64_t{b.*f.u32});
        break;
      case sim_detail::FieldKind::u64:
        c.field(id, f.name, a.*f.u64, b.*f.u64);
        break;
      case sim_detail::FieldKind::flag:
        c.field(id, f.name, a.*f.flag, b.*f.flag);
        break;
    }
  }
}

// "contact[B]" for whole shapes; "contact[B/SUB_A/SUB_B]" between sub-shapes: the body is the
// pair's lower ID, so this is the form --inject takes with BODY = a (inject.hpp).
std::string contact_name(const ContactState& c) {
  std::string name = "contact[" + std::to_string(c.b.value);
  if (c.sub_a != 0 || c.sub_b != 0)
    name += "/" + std::to_string(c.sub_a) + "/" + std::to_string(c.sub_b);
  return name + "]";
}

void diff_contact(Collector& c, const ContactState& a, const ContactState& b) {
  const std::uint32_t id = a.a.value;
  const std::string name = contact_name(a);
  c.field(id, name + ".touching", a.touching, b.touching, "contacts");
  c.field(id, name + ".reported", a.reported, b.reported, "contacts");
  c.field(id, name + ".point_count", std::uint64_t{a.point_count}, std::uint64_t{b.point_count},
          "contacts");
  const std::size_t points = std::min(a.point_count, b.point_count);
  for (std::size_t i = 0; i < points; ++i) {
    const std::string p = name + ".point[" + std::to_string(i) + "].";
    const ContactPointState& pa = a.points[i];
    const ContactPointState& pb = b.points[i];
    c.field(id, p + "feature", std::uint64_t{pa.feature}, std::uint64_t{pb.feature}, "contacts");
    c.field(id, p + "normal_impulse", pa.normal_impulse, pb.normal_impulse, "contacts");
    c.field(id, p + "tangent_impulse_1", pa.tangent_impulse_1, pb.tangent_impulse_1, "contacts");
    c.field(id, p + "tangent_impulse_2", pa.tangent_impulse_2, pb.tangent_impulse_2, "contacts");
  }
}

// A merge of both contact lists, ascending (a, b, sub_a, sub_b); a contact on one side only is
// "present".
void diff_contacts(Collector& c, const std::vector<ContactState>& ca,
                   const std::vector<ContactState>& cb) {
  const auto key = [](const ContactState& x) {
    return std::array<std::uint32_t, 4>{x.a.value, x.b.value, x.sub_a, x.sub_b};
  };
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < ca.size() || j < cb.size()) {
    if (j == cb.size() || (i < ca.size() && key(ca[i]) < key(cb[j]))) {
      c.add("contacts", ca[i].a.value, contact_name(ca[i]) + ".present", "present", "absent");
      ++i;
    } else if (i == ca.size() || key(cb[j]) < key(ca[i])) {
      c.add("contacts", cb[j].a.value, contact_name(cb[j]) + ".present", "absent", "present");
      ++j;
    } else {
      diff_contact(c, ca[i], cb[j]);
      ++i;
      ++j;
    }
  }
}

std::string joint_name(JointId id) {
  return "joint[" + std::to_string(id.value) + "]";
}

// Every field of a record's table (record_fields.hpp), in its order, named "PREFIX.FIELD".
// Records belong to no one body: their lines have body 0 and name the record in the field.
template <class T>
void diff_record_fields(Collector& c, const std::string& prefix,
                        std::span<const sim_detail::RecordField<T>> fields, T a, T b,
                        const char* section) {
  using sim_detail::RecordFieldKind;
  for (const sim_detail::RecordField<T>& f : fields) {
    const std::string field = prefix + f.name;
    switch (f.kind) {
      case RecordFieldKind::fixed:
        c.field(0, field, f.fixed(a), f.fixed(b), section);
        break;
      case RecordFieldKind::vec3:
        c.vec(0, field, f.vec3(a), f.vec3(b), section);
        break;
      case RecordFieldKind::quat:
        c.quat(0, field, f.quat(a), f.quat(b), section);
        break;
      case RecordFieldKind::u32:
        c.field(0, field, std::uint64_t{f.u32(a)}, std::uint64_t{f.u32(b)}, section);
        break;
      case RecordFieldKind::u64:
        c.field(0, field, f.u64(a), f.u64(b), section);
        break;
      case RecordFieldKind::flag:
        c.field(0, field, f.flag(a), f.flag(b), section);
        break;
    }
  }
}

// A joint's identity (type, bodies), then every field of its table (joint_fields.hpp).
void diff_joint(Collector& c, const JointState& a, const JointState& b) {
  const std::string name = joint_name(a.id) + ".";
  const char* section = "joints";
  c.field(0, name + "type", a.def.type, b.def.type, section);
  c.field(0, name + "body_a", std::uint64_t{a.def.body_a.value}, std::uint64_t{b.def.body_a.value},
          section);
  c.field(0, name + "body_b", std::uint64_t{a.def.body_b.value}, std::uint64_t{b.def.body_b.value},
          section);
  diff_record_fields(c, name, sim_detail::joint_fields(), a, b, section);
}

// ---- Sections: each a differ that lists its fields; any other section is named by its hash ----

/// One entry of a state's "geometry" section (state_geometry.cpp): what the state needs the
/// restoring world to hold under ID index + 1.
struct NamedGeometry {
  std::uint8_t type = 0;
  std::uint64_t hash = 0;

  friend bool operator==(const NamedGeometry&, const NamedGeometry&) = default;
};

/// The geometry a state names, read from its "geometry" section without restoring it (the world
/// at hand may lack it); an empty list for a state without that section, which restore refuses
/// with its own message.
Expected<std::vector<NamedGeometry>> named_geometry(std::span<const std::uint8_t> bytes) {
  auto sections = read_state_sections(bytes);
  if (!sections) return Status::error("invalid state: " + sections.message());
  std::vector<NamedGeometry> out;
  for (const StateSection& section : *sections) {
    if (section.name != "geometry") continue;
    const std::size_t end = section.payload_offset + section.payload.size();
    ByteReader r(bytes.first(end), section.payload_offset);
    const std::uint64_t count = r.var("geometry count");
    for (std::uint64_t i = 0; i < count && r.ok(); ++i) {
      NamedGeometry g;
      g.type = r.u8("geometry type");
      g.hash = r.u64("geometry hash");
      if (r.ok()) out.push_back(g);
    }
    if (!r.ok()) return Status::error("invalid state: section \"geometry\": " + r.error());
  }
  return out;
}

std::string show(const NamedGeometry& g) {
  using sim_detail::GeometryType;
  const bool known = g.type >= static_cast<std::uint8_t>(GeometryType::convex_hull) &&
                     g.type <= static_cast<std::uint8_t>(GeometryType::compound);
  const std::string type = known ? sim_detail::geometry_type_name(static_cast<GeometryType>(g.type))
                                 : "unknown type " + std::to_string(g.type);
  return type + ", content hash " + hex(g.hash);
}

/// What a section's differ compares: the restored worlds (null when that side was not restored)
/// and the geometry lists read from the bytes.
struct Sides {
  const World* a;
  const World* b;
  const std::vector<NamedGeometry>& geometry_a;
  const std::vector<NamedGeometry>& geometry_b;
};

// Entry by entry, by ID: a type and content hash on each side, or "absent".
void diff_geometry(Collector& c, const Sides& w) {
  const std::size_t n = std::max(w.geometry_a.size(), w.geometry_b.size());
  for (std::size_t i = 0; i < n; ++i) {
    const bool in_a = i < w.geometry_a.size();
    const bool in_b = i < w.geometry_b.size();
    if (in_a && in_b && w.geometry_a[i] == w.geometry_b[i]) continue;
    c.add("geometry", 0, "geometry[" + std::to_string(i + 1) + "]",
          in_a ? show(w.geometry_a[i]) : "absent", in_b ? show(w.geometry_b[i]) : "absent");
  }
}

void diff_globals(Collector& c, const Sides& w) {
  if (w.a->frame() != w.b->frame())
    c.add("globals", 0, "frame", show(w.a->frame()), show(w.b->frame()));
  if (!(w.a->def() == w.b->def()))
    c.add("globals", 0, "world definition", "(differs)", "(differs)");
}

void diff_rng(Collector& c, const Sides& w) {
  const Rng::State& ra = w.a->rng().state();
  const Rng::State& rb = w.b->rng().state();
  for (std::size_t i = 0; i < ra.size(); ++i)
    if (ra[i] != rb[i])
      c.add("rng", 0, "state[" + std::to_string(i) + "]", show(ra[i]), show(rb[i]));
}

// A merge of both ascending ID lists.
void diff_bodies(Collector& c, const Sides& w) {
  const std::vector<BodyId> ia = w.a->body_ids();
  const std::vector<BodyId> ib = w.b->body_ids();
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < ia.size() || j < ib.size()) {
    if (j == ib.size() || (i < ia.size() && ia[i].value < ib[j].value)) {
      c.add("bodies", ia[i].value, "present", "present", "absent");
      ++i;
    } else if (i == ia.size() || ib[j].value < ia[i].value) {
      c.add("bodies", ib[j].value, "present", "absent", "present");
      ++j;
    } else {
      diff_body(c, w.a->body(ia[i]).value(), w.b->body(ib[j]).value());
      ++i;
      ++j;
    }
  }
}

void diff_contact_cache(Collector& c, const Sides& w) {
  diff_contacts(c, w.a->contacts(), w.b->contacts());
}

// A merge of both ascending joint ID lists; a joint on one side only is "present".
void diff_joints(Collector& c, const Sides& w) {
  const std::vector<JointId> ia = w.a->joint_ids();
  const std::vector<JointId> ib = w.b->joint_ids();
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < ia.size() || j < ib.size()) {
    if (j == ib.size() || (i < ia.size() && ia[i] < ib[j])) {
      c.add("joints", 0, joint_name(ia[i]) + ".present", "present", "absent");
      ++i;
    } else if (i == ia.size() || ib[j] < ia[i]) {
      c.add("joints", 0, joint_name(ib[j]) + ".present", "absent", "present");
      ++j;
    } else {
      diff_joint(c, w.a->joint(ia[i]).value(), w.b->joint(ib[j]).value());
      ++i;
      ++j;
    }
  }
}

std::string vehicle_name(VehicleId id) {
  return "vehicle[" + std::to_string(id.value) + "]";
}

// A vehicle's own fields, then its lists: the torque curve, the gear ratios, each wheel's
// definition and state ("vehicle[1].wheel[2].angular_velocity"), each axle. A list of another
// length is named by its count.
void diff_vehicle(Collector& c, const VehicleState& a, const VehicleState& b) {
  const char* section = "vehicles";
  const std::string name = vehicle_name(a.id) + ".";
  diff_record_fields(c, name, sim_detail::vehicle_fields(), a, b, section);
  const auto count = [&](const std::string& list, std::size_t na, std::size_t nb) {
    c.field(0, name + list + ".count", std::uint64_t{na}, std::uint64_t{nb}, section);
    return na == nb;
  };
  const std::vector<TorquePoint>& ta = a.def.engine.torque_curve;
  const std::vector<TorquePoint>& tb = b.def.engine.torque_curve;
  if (count("engine.torque_curve", ta.size(), tb.size())) {
    for (std::size_t i = 0; i < ta.size(); ++i) {
      const std::string at = name + "engine.torque_curve[" + std::to_string(i) + "].";
      c.field(0, at + "rpm", ta[i].rpm, tb[i].rpm, section);
      c.field(0, at + "torque", ta[i].torque, tb[i].torque, section);
    }
  }
  if (count("gear_ratios", a.def.gear_ratios.size(), b.def.gear_ratios.size())) {
    for (std::size_t i = 0; i < a.def.gear_ratios.size(); ++i)
      c.field(0, name + "gear_ratios[" + std::to_string(i) + "]", a.def.gear_ratios[i],
              b.def.gear_ratios[i], section);
  }
  if (count("wheels", a.wheels.size(), b.wheels.size())) {
    for (std::size_t i = 0; i < a.wheels.size(); ++i) {
      const std::string at = name + "wheel[" + std::to_string(i) + "].";
      diff_record_fields(c, at, sim_detail::wheel_def_fields(), a.def.wheels[i], b.def.wheels[i],
                         section);
      diff_record_fields(c, at, sim_detail::wheel_state_fields(), a.wheels[i], b.wheels[i],
                         section);
    }
  }
  if (count("axles", a.def.axles.size(), b.def.axles.size())) {
    for (std::size_t i = 0; i < a.def.axles.size(); ++i)
      diff_record_fields(c, name + "axle[" + std::to_string(i) + "].", sim_detail::axle_fields(),
                         a.def.axles[i], b.def.axles[i], section);
  }
}

// A merge of both ascending vehicle ID lists; a vehicle on one side only is "present".
void diff_vehicles(Collector& c, const Sides& w) {
  const std::vector<VehicleId> ia = w.a->vehicle_ids();
  const std::vector<VehicleId> ib = w.b->vehicle_ids();
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < ia.size() || j < ib.size()) {
    if (j == ib.size() || (i < ia.size() && ia[i] < ib[j])) {
      c.add("vehicles", 0, vehicle_name(ia[i]) + ".present", "present", "absent");
      ++i;
    } else if (i == ia.size() || ib[j] < ia[i]) {
      c.add("vehicles", 0, vehicle_name(ib[j]) + ".present", "absent", "present");
      ++j;
    } else {
      diff_vehicle(c, w.a->vehicle(ia[i]).value(), w.b->vehicle(ib[j]).value());
      ++i;
      ++j;
    }
  }
}

std::string character_name(CharacterId id) {
  return "character[" + std::to_string(id.value) + "]";
}

// A merge of both ascending character ID lists; a character on one side only is "present".
void diff_characters(Collector& c, const Sides& w) {
  const std::vector<CharacterId> ia = w.a->character_ids();
  const std::vector<CharacterId> ib = w.b->character_ids();
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < ia.size() || j < ib.size()) {
    if (j == ib.size() || (i < ia.size() && ia[i] < ib[j])) {
      c.add("characters", 0, character_name(ia[i]) + ".present", "present", "absent");
      ++i;
    } else if (i == ia.size() || ib[j] < ia[i]) {
      c.add("characters", 0, character_name(ib[j]) + ".present", "absent", "present");
      ++j;
    } else {
      diff_record_fields(c, character_name(ia[i]) + ".", sim_detail::character_fields(),
                         w.a->character(ia[i]).value(), w.b->character(ib[j]).value(),
                         "characters");
      ++i;
      ++j;
    }
  }
}

std::string group_name(ParticleGroupId id) {
  return "particle_group[" + std::to_string(id.value) + "]";
}

// A group's identity (type, definition), its state (flags, sleep time, force, tether impulse),
// its attachments, its particles (particle[I].position / velocity) and its broken constraints
// (constraint[K].broken, K an index into the constraints the definition builds). Groups belong
// to no one body: their lines have body 0 and name the group in the field, the form --inject
// takes (inject.hpp).
void diff_group(Collector& c, const sim_detail::ParticleGroup& a,
                const sim_detail::ParticleGroup& b) {
  const std::string name = group_name(a.id) + ".";
  const char* section = "particles";
  c.field(0, name + "type", a.type, b.type, section);
  if (a.type == b.type && !(a.def == b.def))
    c.add(section, 0, name + "definition", "(differs)", "(differs)");
  c.field(0, name + "awake", a.awake, b.awake, section);
  c.field(0, name + "sleep_time", a.sleep_time, b.sleep_time, section);
  c.vec(0, name + "force", a.force, b.force, section);
  c.field(0, name + "tether_impulse", a.tether_impulse, b.tether_impulse, section);
  c.field(0, name + "attachment_count", std::uint64_t{a.attachments.size()},
          std::uint64_t{b.attachments.size()}, section);
  for (std::size_t k = 0; k < std::min(a.attachments.size(), b.attachments.size()); ++k) {
    const std::string at = name + "attachment[" + std::to_string(k) + "].";
    const sim_detail::Attachment& x = a.attachments[k];
    const sim_detail::Attachment& y = b.attachments[k];
    c.field(0, at + "particle", std::uint64_t{x.particle}, std::uint64_t{y.particle}, section);
    c.field(0, at + "body", std::uint64_t{x.body}, std::uint64_t{y.body}, section);
    c.vec(0, at + "local", x.local, y.local, section);
  }
  c.field(0, name + "particle_count", std::uint64_t{a.size()}, std::uint64_t{b.size()}, section);
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    const std::string p = name + "particle[" + std::to_string(i) + "].";
    c.vec(0, p + "position", a.positions[i], b.positions[i], section);
    c.vec(0, p + "velocity", a.velocities[i], b.velocities[i], section);
  }
  c.field(0, name + "broken_count", std::uint64_t{a.broken.size()}, std::uint64_t{b.broken.size()},
          section);
  // A merge of both ascending lists: a constraint broken on one side only.
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < a.broken.size() || j < b.broken.size()) {
    if (j == b.broken.size() || (i < a.broken.size() && a.broken[i] < b.broken[j])) {
      c.add(section, 0, name + "constraint[" + std::to_string(a.broken[i]) + "].broken", "true",
            "false");
      ++i;
    } else if (i == a.broken.size() || b.broken[j] < a.broken[i]) {
      c.add(section, 0, name + "constraint[" + std::to_string(b.broken[j]) + "].broken", "false",
            "true");
      ++j;
    } else {
      ++i;
      ++j;
    }
  }
}

// A merge of both ascending group ID lists; a group on one side only is "present".
void diff_particles(Collector& c, const Sides& w) {
  const auto& ga = sim_detail::WorldAccess::of(*w.a).particle_groups;
  const auto& gb = sim_detail::WorldAccess::of(*w.b).particle_groups;
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < ga.size() || j < gb.size()) {
    if (j == gb.size() || (i < ga.size() && ga[i].id < gb[j].id)) {
      c.add("particles", 0, group_name(ga[i].id) + ".present", "present", "absent");
      ++i;
    } else if (i == ga.size() || gb[j].id < ga[i].id) {
      c.add("particles", 0, group_name(gb[j].id) + ".present", "absent", "present");
      ++j;
    } else {
      diff_group(c, ga[i], gb[j]);
      ++i;
      ++j;
    }
  }
}

struct SectionDiffer {
  std::string_view name;
  void (*diff)(Collector& c, const Sides& w);
  bool needs_worlds = true;  ///< reads the restored worlds (else only the bytes)
};

/// A described field's value in a game state (little-endian), or "absent" past its end.
std::string game_value(std::span<const std::uint8_t> bytes, const GameField& f) {
  const std::size_t size = game_field_size(f.type);
  if (std::size_t{f.offset} + size > bytes.size()) return "absent";
  std::uint64_t raw = 0;
  for (std::size_t k = 0; k < size; ++k)
    raw |= std::uint64_t{bytes[f.offset + k]} << (8 * k);
  const auto sign_extended = [raw, size]() {
    const unsigned shift = static_cast<unsigned>(64 - 8 * size);
    return static_cast<std::int64_t>(raw << shift) >> shift;
  };
  switch (f.type) {
    case GameFieldType::i8:
    case GameFieldType::i16:
    case GameFieldType::i32:
    case GameFieldType::i64:
      return std::to_string(sign_extended()) + " (" + hex(raw) + ")";
    case GameFieldType::fixed:
      return show(Fixed::from_raw(static_cast<std::int64_t>(raw)));
    default:
      return show(raw);
  }
}

/// Bytes [from, to) as hex digits, "0a0b0c".
std::string hex_bytes(std::span<const std::uint8_t> bytes, std::size_t from, std::size_t to) {
  std::string out;
  for (std::size_t i = from; i < to; ++i) {
    char digits[3];
    std::snprintf(digits, sizeof digits, "%02x", bytes[i]);
    out += digits;
  }
  return out;
}

// The game's own state: its size, then each described field (World::describe_game_state) in the
// description's order, then the differing runs of bytes no field covers ("bytes[12..15]").
void diff_game(Collector& c, const Sides& w) {
  const std::span<const std::uint8_t> a = w.a->game_state();
  const std::span<const std::uint8_t> b = w.b->game_state();
  if (a.size() != b.size())
    c.add("game", 0, "size", show(std::uint64_t{a.size()}), show(std::uint64_t{b.size()}));
  const std::span<const GameField> fields = w.a->game_state_fields();
  const std::size_t common = std::min(a.size(), b.size());
  std::vector<bool> covered(common, false);
  for (const GameField& f : fields) {
    const std::string va = game_value(a, f);
    const std::string vb = game_value(b, f);
    if (va != vb) c.add("game", 0, f.name, va, vb);
    const std::size_t end = std::min(common, std::size_t{f.offset} + game_field_size(f.type));
    for (std::size_t i = f.offset; i < end; ++i)
      covered[i] = true;
  }
  constexpr std::size_t longest_shown = 16;  // bytes of a run printed; a longer one is cut
  for (std::size_t i = 0; i < common;) {
    if (covered[i] || a[i] == b[i]) {
      ++i;
      continue;
    }
    std::size_t end = i + 1;
    while (end < common && !covered[end] && a[end] != b[end])
      ++end;
    const std::size_t shown = std::min(end, i + longest_shown);
    const std::string more = shown < end ? "..." : "";
    c.add("game", 0, "bytes[" + std::to_string(i) + ".." + std::to_string(end - 1) + "]",
          hex_bytes(a, i, shown) + more, hex_bytes(b, i, shown) + more);
    i = end;
  }
}

/// A new section of the World's state adds its differ here.
constexpr SectionDiffer kDiffers[] = {
    {"globals", diff_globals},           //
    {"geometry", diff_geometry, false},  //
    {"rng", diff_rng},                   //
    {"bodies", diff_bodies},             //
    {"contacts", diff_contact_cache},    //
    {"joints", diff_joints},             //
    {"particles", diff_particles},       //
    {"vehicles", diff_vehicles},         //
    {"characters", diff_characters},     //
    {"game", diff_game},                 //
};

/// The hashes of a state's sections from its bytes (a state that may not restore here), and its
/// frame: the first field of "globals" (state_io.cpp), 0 when unreadable.
StateHashes hashes_of(std::span<const std::uint8_t> bytes, std::uint64_t& frame) {
  StateHashes h;
  h.total = hash_bytes(bytes);
  frame = 0;
  if (auto sections = read_state_sections(bytes)) {
    for (const StateSection& s : *sections) {
      h.sections.push_back({std::string(s.name), section_hash(s)});
      if (s.name != "globals") continue;
      ByteReader r(bytes.first(s.payload_offset + s.payload.size()), s.payload_offset);
      const std::uint64_t f = r.u64("frame");
      if (r.ok()) frame = f;
    }
  }
  return h;
}

/// Every section name of either side: A's in order, then those only B has.
std::vector<std::string> section_names(const StateHashes& a, const StateHashes& b) {
  std::vector<std::string> names;
  for (const SectionHash& h : a.sections)
    names.push_back(h.name);
  for (const SectionHash& h : b.sections)
    if (std::find(names.begin(), names.end(), h.name) == names.end()) names.push_back(h.name);
  return names;
}

}  // namespace

std::vector<std::string> differing_subsystems(const StateHashes& a, const StateHashes& b) {
  std::vector<std::string> out;
  for (const std::string& name : section_names(a, b)) {
    const auto hash_of = [&](const StateHashes& h) -> const SectionHash* {
      for (const SectionHash& s : h.sections)
        if (s.name == name) return &s;
      return nullptr;
    };
    const SectionHash* ha = hash_of(a);
    const SectionHash* hb = hash_of(b);
    if (ha == nullptr || hb == nullptr || ha->hash != hb->hash) out.push_back(name);
  }
  return out;
}

Expected<StateDiff> diff_states(const World& geometry, std::span<const std::uint8_t> a,
                                std::span<const std::uint8_t> b, std::size_t max_fields) {
  auto geometry_a = named_geometry(a);
  if (!geometry_a) return Status::error("state A: " + geometry_a.message());
  auto geometry_b = named_geometry(b);
  if (!geometry_b) return Status::error("state B: " + geometry_b.message());
  // Restored over copies of `geometry`: restore() keeps a world's geometry and checks the state's
  // against it (the bodies of `geometry` are replaced).
  World wa(geometry);
  World wb(geometry);
  const Status restored_a = wa.restore(a);
  const Status restored_b = wb.restore(b);
  const bool same_geometry = geometry_a.value() == geometry_b.value();
  // A state that cannot be restored is an error, unless the states name different geometry: then
  // that difference is the answer, and it is listed with the sections' hashes.
  const auto failed = [&](const char* side, const Status& s) -> Status {
    std::string message = std::string("state ") + side + ": " + s.message();
    if (s.message().find("geometry") != std::string::npos)
      message +=
          " (a diff restores both states against a world that holds their geometry: "
          "the scenario's or game's, e.g. detsim diff --scenario NAME)";
    return Status::error(message);
  };
  if (!restored_a && (same_geometry || restored_a.message().find("geometry") == std::string::npos))
    return failed("A", restored_a);
  if (!restored_b && (same_geometry || restored_b.message().find("geometry") == std::string::npos))
    return failed("B", restored_b);
  const bool both = restored_a && restored_b;

  StateDiff out;
  out.a = restored_a ? wa.hashes() : hashes_of(a, out.frame_a);
  out.b = restored_b ? wb.hashes() : hashes_of(b, out.frame_b);
  if (restored_a) out.frame_a = wa.frame();
  if (restored_b) out.frame_b = wb.frame();
  if (!both)
    out.note = std::string("state ") + (restored_a ? "B" : "A") +
               " names geometry that the world given does not hold (" +
               (restored_a ? restored_b : restored_a).message() +
               "): only the geometry and the sections' hashes are compared";
  Collector c(out, max_fields);

  // The count is saved with the bodies, not the globals, but it is a global fact: listed first,
  // whichever section's hash differs, and as a line of the globals section.
  const std::size_t start = out.fields.size() + out.omitted;
  if (both && wa.body_count() != wb.body_count())
    c.add("globals", 0, "body count", show(std::uint64_t{wa.body_count()}),
          show(std::uint64_t{wb.body_count()}));
  const Sides sides{&wa, &wb, geometry_a.value(), geometry_b.value()};
  std::vector<std::string> sections = differing_subsystems(out.a, out.b);
  if (!both) {
    // The geometry is why the rest could not be compared: it comes first.
    const auto g = std::find(sections.begin(), sections.end(), "geometry");
    if (g != sections.end()) std::rotate(sections.begin(), g, g + 1);
  }
  for (const std::string& name : sections) {
    const std::size_t before = name == "globals" ? start : out.fields.size() + out.omitted;
    for (const SectionDiffer& d : kDiffers) {
      if (d.name == name && (both || !d.needs_worlds)) d.diff(c, sides);
    }
    // A section may hold more than its accessors show (the next body ID, a contact's manifold
    // flags): name the section's hashes then.
    if (out.fields.size() + out.omitted == before)
      c.add(name.c_str(), 0, "hash", show(out.a.section(name)), show(out.b.section(name)));
  }
  return out;
}

Expected<StateDiff> diff_states(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b,
                                std::size_t max_fields) {
  return diff_states(World(), a, b, max_fields);
}

}  // namespace detsim

// The canonical state encoding (docs/STATE.md): save, restore and the hashes.
//
// Writer and reader of each part sit side by side so that a field added to one is seen missing
// from the other. The globals and the RNG are fixed-width little-endian; the bodies and contacts,
// which are most of a snapshot, use vars (bytes.hpp) and write what bodies share once, in property
// sets. The restore reads into a scratch WorldState and validates every field before the world is
// replaced, so bad bytes change nothing; it accepts only canonical bytes (the shortest vars, sets
// in first-use order, flags that match their values), so a state has exactly one encoding.
#include <algorithm>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

#include <detsim/core/hash.hpp>

#include "shapes.hpp"
#include "world_state.hpp"

namespace detsim {

namespace sim_detail {

namespace {

constexpr std::uint32_t kMagic = 0x4D495344;  // "DSIM" read as little-endian bytes
constexpr std::uint32_t kVersion = state_encoding_version;

// Smallest encodings, to bound counts by the bytes that remain before allocating.
constexpr std::size_t kMinPropertyBytes = 1 + 1 + 1 + 3 + 4 + 4 + 4 + 1;
constexpr std::size_t kMinBodyBytes = 1 + 1 + 1 + 3 + 4 + 3 + 3 + 1;
constexpr std::size_t kMinContactBytes = 1 + 1 + 1;

// Body flags.
constexpr std::uint8_t kAwake = 1;
constexpr std::uint8_t kHasUserData = 2;
constexpr std::uint8_t kHasForce = 4;
constexpr std::uint8_t kHasTorque = 8;
// Property-set flags.
constexpr std::uint8_t kSensor = 1;
constexpr std::uint8_t kCcd = 2;
// A contact's point byte: the count in bits 0-2, then the reported flag.
constexpr std::uint8_t kPointCountMask = 7;
constexpr std::uint8_t kReported = 8;

std::uint64_t xxh3(const std::vector<std::uint8_t>& bytes) {
  return hash64(bytes);
}

void write_def(const WorldDef& d, ByteWriter& w) {
  w.vec3(d.gravity);
  w.fixed(d.dt);
  w.u32(d.substeps);
  w.u32(d.iterations);
  w.u64(d.seed);
  w.fixed(d.max_linear_speed);
  w.fixed(d.max_angular_speed);
  w.fixed(d.contact_hertz);
  w.fixed(d.contact_damping_ratio);
  w.fixed(d.contact_push_max);
  w.fixed(d.restitution_threshold);
  w.fixed(d.linear_slop);
  w.fixed(d.speculative_distance);
  w.boolean(d.enable_sleep);
  w.fixed(d.sleep_linear_speed);
  w.fixed(d.sleep_angular_speed);
  w.fixed(d.time_to_sleep);
}

WorldDef read_def(ByteReader& r) {
  WorldDef d;
  d.gravity = r.vec3("gravity");
  d.dt = r.fixed("dt");
  d.substeps = r.u32("substeps");
  d.iterations = r.u32("iterations");
  d.seed = r.u64("seed");
  d.max_linear_speed = r.fixed("max linear speed");
  d.max_angular_speed = r.fixed("max angular speed");
  d.contact_hertz = r.fixed("contact hertz");
  d.contact_damping_ratio = r.fixed("contact damping ratio");
  d.contact_push_max = r.fixed("contact push max");
  d.restitution_threshold = r.fixed("restitution threshold");
  d.linear_slop = r.fixed("linear slop");
  d.speculative_distance = r.fixed("speculative distance");
  d.enable_sleep = r.boolean("enable sleep");
  d.sleep_linear_speed = r.fixed("sleep linear speed");
  d.sleep_angular_speed = r.fixed("sleep angular speed");
  d.time_to_sleep = r.fixed("time to sleep");
  return d;
}

// A shape: its type, then the fields its kind writes (shapes.hpp).
void write_shape(const Shape& s, ByteWriter& w) {
  w.u8(static_cast<std::uint8_t>(s.type));
  shape_kind(s.type).write(s, w);
}

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

// ---- Property sets: what a body has that the simulation never changes by itself ----

/// The property fields of a BodyState. Comparing and writing go through this one struct, so that
/// two bodies share a set exactly when their sets' bytes would be equal.
struct Properties {
  BodyType type = BodyType::dynamic;
  Shape shape{};
  Fixed mass{};
  Vec3 inertia{};
  Fixed friction{};
  Fixed restitution{};
  Fixed linear_damping{};
  Fixed angular_damping{};
  std::uint32_t layer = 0;
  std::uint32_t mask = 0;
  bool sensor = false;
  bool ccd = false;

  friend bool operator==(const Properties&, const Properties&) noexcept = default;
};

Properties properties_of(const BodyState& b) noexcept {
  return {b.type,           b.shape,           b.mass,  b.inertia, b.friction, b.restitution,
          b.linear_damping, b.angular_damping, b.layer, b.mask,    b.sensor,   b.ccd};
}

void set_properties(BodyState& b, const Properties& p) noexcept {
  b.type = p.type;
  b.shape = p.shape;
  b.mass = p.mass;
  b.inertia = p.inertia;
  b.friction = p.friction;
  b.restitution = p.restitution;
  b.linear_damping = p.linear_damping;
  b.angular_damping = p.angular_damping;
  b.layer = p.layer;
  b.mask = p.mask;
  b.sensor = p.sensor;
  b.ccd = p.ccd;
}

void write_properties(const Properties& p, ByteWriter& w) {
  w.u8(static_cast<std::uint8_t>(p.type));
  write_shape(p.shape, w);
  w.var_fixed(p.mass);
  w.var_vec3(p.inertia);
  w.var_fixed(p.friction);
  w.var_fixed(p.restitution);
  w.var_fixed(p.linear_damping);
  w.var_fixed(p.angular_damping);
  w.u32(p.layer);
  w.u32(p.mask);
  w.u8(static_cast<std::uint8_t>((p.sensor ? kSensor : 0U) | (p.ccd ? kCcd : 0U)));
}

Properties read_properties(ByteReader& r) {
  Properties p;
  const std::size_t type_at = r.offset();
  const std::uint8_t type = r.u8("body type");
  if (type > static_cast<std::uint8_t>(BodyType::dynamic))
    r.fail_at(type_at, "body type", "0 (static), 1 (kinematic) or 2 (dynamic)");
  p.type = static_cast<BodyType>(type);
  p.shape = read_shape(r);
  p.mass = r.var_fixed("body mass");
  p.inertia = r.var_vec3("body inertia");
  p.friction = r.var_fixed("body friction");
  p.restitution = r.var_fixed("body restitution");
  p.linear_damping = r.var_fixed("body linear damping");
  p.angular_damping = r.var_fixed("body angular damping");
  p.layer = r.u32("body layer");
  p.mask = r.u32("body mask");
  const std::size_t flags_at = r.offset();
  const std::uint8_t flags = r.u8("property flags");
  if (flags > (kSensor | kCcd))
    r.fail_at(flags_at, "property flags", "only bits 0 (sensor), 1 (CCD)");
  p.sensor = (flags & kSensor) != 0;
  p.ccd = (flags & kCcd) != 0;
  return p;
}

// Semantic checks of a property set read from bytes; "" when valid.
std::string check_properties(const Properties& p) {
  if (auto e = check_shape(p.shape, p.type); !e.empty()) return e;
  if (p.mass < Fixed::zero()) return "mass must be >= 0";
  if (p.type == BodyType::dynamic && (p.mass <= Fixed::zero() || p.inertia.x <= Fixed::zero() ||
                                      p.inertia.y <= Fixed::zero() || p.inertia.z <= Fixed::zero()))
    return "a dynamic body needs a positive mass and moments of inertia";
  if (p.friction < Fixed::zero() || p.restitution < Fixed::zero() || p.restitution > Fixed::one() ||
      p.linear_damping < Fixed::zero() || p.angular_damping < Fixed::zero())
    return "material or damping out of range";
  return {};
}

// ---- Bodies: the ID step, the property set, then what moves ----

/// Writes the record of `b`, whose ID follows `previous_id` and whose property set is `set`.
void write_record(const BodyState& b, std::uint32_t previous_id, std::uint32_t set, ByteWriter& w) {
  const bool has_force = b.force != Vec3{};
  const bool has_torque = b.torque != Vec3{};
  w.var(b.id.value - previous_id);
  w.var(set);
  w.u8(static_cast<std::uint8_t>((b.awake ? kAwake : 0U) | (b.user_data != 0 ? kHasUserData : 0U) |
                                 (has_force ? kHasForce : 0U) | (has_torque ? kHasTorque : 0U)));
  w.var_vec3(b.position);
  w.var_quat(b.orientation);
  w.var_vec3(b.linear_velocity);
  w.var_vec3(b.angular_velocity);
  w.var_fixed(b.sleep_time);
  if (b.user_data != 0) w.var(b.user_data);
  if (has_force) w.var_vec3(b.force);
  if (has_torque) w.var_vec3(b.torque);
}

/// Reads a body record into `b` (not its property fields); `id_step` and `set` are returned for
/// the caller to check against the bodies and sets before it.
void read_record(ByteReader& r, BodyState& b, std::uint32_t& id_step, std::uint32_t& set) {
  id_step = r.var32("body id step");
  set = r.var32("body property set");
  const std::size_t flags_at = r.offset();
  const std::uint8_t flags = r.u8("body flags");
  if (flags > (kAwake | kHasUserData | kHasForce | kHasTorque))
    r.fail_at(flags_at, "body flags", "only bits 0 (awake), 1 (user data), 2 (force), 3 (torque)");
  b.awake = (flags & kAwake) != 0;
  b.position = r.var_vec3("body position");
  b.orientation = r.var_quat("body orientation");
  b.linear_velocity = r.var_vec3("body linear velocity");
  b.angular_velocity = r.var_vec3("body angular velocity");
  b.sleep_time = r.var_fixed("body sleep time");
  // A value flagged present must not be zero: zero is written by leaving the flag clear.
  const auto present = [&](const char* what, bool nonzero) {
    if (!nonzero) r.fail_at(flags_at, what, "a value that is not zero when its flag is set");
  };
  b.user_data = 0;
  b.force = {};
  b.torque = {};
  if ((flags & kHasUserData) != 0) {
    b.user_data = r.var("body user data");
    present("body user data", b.user_data != 0);
  }
  if ((flags & kHasForce) != 0) {
    b.force = r.var_vec3("body force");
    present("body force", b.force != Vec3{});
  }
  if ((flags & kHasTorque) != 0) {
    b.torque = r.var_vec3("body torque");
    present("body torque", b.torque != Vec3{});
  }
}

// Semantic checks of a body's moving part; "" when valid.
std::string check_record(const BodyState& b) {
  if (auto e = check_orientation(b.orientation); !e.empty()) return e;
  if (b.sleep_time < Fixed::zero()) return "sleep time must be >= 0";
  if (b.type == BodyType::static_body && b.awake) return "a static body cannot be awake";
  return {};
}

// ---- Contacts ----

// A feature (collide_util.hpp: kind << 8 | index, kind < 4) is written as index * 4 + kind.
std::uint32_t pack_feature(std::uint32_t f) noexcept {
  return ((f & 0xFFU) << 2) | ((f >> 8) & 3U);
}
std::uint32_t unpack_feature(std::uint32_t v) noexcept {
  return ((v & 3U) << 8) | (v >> 2);
}
constexpr std::uint32_t kMaxPackedFeature = (0xFFU << 2) | 3U;

Contact read_contact(ByteReader& r, std::uint32_t previous_a) {
  Contact c;
  const std::size_t a_at = r.offset();
  const std::uint32_t a_step = r.var32("contact body a step");
  if (r.ok() && a_step > 0xFFFFFFFFU - previous_a)
    r.fail_at(a_at, "contact body a step", "an ID below 2^32");
  c.a = previous_a + a_step;
  const std::size_t b_at = r.offset();
  const std::uint32_t b_step = r.var32("contact body b - a");
  if (r.ok() && (b_step == 0 || b_step > 0xFFFFFFFFU - c.a))
    r.fail_at(b_at, "contact body b - a", "at least 1 (a < b) and an ID below 2^32");
  c.b = c.a + b_step;
  const std::size_t points_at = r.offset();
  const std::uint8_t points = r.u8("contact points");
  if ((points & ~(kPointCountMask | kReported)) != 0 || (points & kPointCountMask) > 4)
    r.fail_at(points_at, "contact points", "a count of 0-4 in bits 0-2 and bit 3 (reported)");
  c.point_count = points & kPointCountMask;
  c.touching = c.point_count > 0;
  c.reported = (points & kReported) != 0;
  for (std::size_t p = 0; p < c.point_count && r.ok(); ++p) {
    std::uint32_t feature = 0;
    for (int side = 0; side < 2; ++side) {
      const std::size_t at = r.offset();
      const std::uint32_t v = r.var32("contact feature");
      if (v > kMaxPackedFeature) r.fail_at(at, "contact feature", "index * 4 + kind, index < 256");
      feature |= unpack_feature(v) << (16 * side);
    }
    c.cached[p].feature = feature;
    c.cached[p].normal_impulse = r.var_fixed("contact normal impulse");
    c.cached[p].tangent_impulse_1 = r.var_fixed("contact tangent impulse");
    c.cached[p].tangent_impulse_2 = r.var_fixed("contact tangent impulse");
  }
  return c;
}

}  // namespace

void write_globals(const WorldState& s, ByteWriter& w) {
  w.u64(s.frame);
  w.u32(s.next_id);
  write_def(s.def, w);
}

void write_body(const BodyState& b, ByteWriter& w) {
  write_properties(properties_of(b), w);
  write_record(b, 0, 0, w);
}

void write_contact(const Contact& c, std::uint32_t previous_a, ByteWriter& w) {
  w.var(c.a - previous_a);
  w.var(c.b - c.a);
  w.u8(static_cast<std::uint8_t>(c.point_count | (c.reported ? kReported : 0U)));
  for (std::size_t p = 0; p < c.point_count; ++p) {
    const std::uint32_t f = c.cached[p].feature;
    w.var(pack_feature(f & 0xFFFFU));
    w.var(pack_feature(f >> 16));
    w.var_fixed(c.cached[p].normal_impulse);
    w.var_fixed(c.cached[p].tangent_impulse_1);
    w.var_fixed(c.cached[p].tangent_impulse_2);
  }
}

namespace {

void write_rng(const Rng& rng, ByteWriter& w) {
  for (const std::uint64_t word : rng.state())
    w.u64(word);
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
  Properties previous;
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    const Properties p = properties_of(s.bodies[i]);
    if (i > 0 && p == previous) {
      set_of[i] = set_of[i - 1];
      continue;
    }
    previous = p;
    key.clear();
    write_properties(p, key);
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

void write_contacts(const WorldState& s, ByteWriter& w) {
  w.u32(static_cast<std::uint32_t>(s.contacts.size()));
  std::uint32_t previous_a = 0;
  for (const Contact& c : s.contacts) {
    write_contact(c, previous_a, w);
    previous_a = c.a;
  }
}

// Reads and validates a whole state; on failure returns false with `error` set.
bool read_state(std::span<const std::uint8_t> bytes, WorldState& s, std::string& error) {
  ByteReader r(bytes);
  // A failure of the reader already names its byte; a semantic one names the field's start.
  const auto failed = [&](const std::string& message) {
    error = "invalid state: " + message;
    return false;
  };
  const auto failed_at = [&](std::size_t at, const std::string& message) {
    return failed("byte " + std::to_string(at) + ": " + message);
  };
  if (r.u32("magic") != kMagic) r.fail_at(0, "magic", "\"DSIM\" (not a detsim state)");
  const std::uint32_t version = r.u32("version");
  if (r.ok() && version != kVersion) {
    return failed_at(4, "state encoding version " + std::to_string(version) +
                            ", this build reads " + std::to_string(kVersion));
  }
  s.frame = r.u64("frame");
  const std::size_t next_id_at = r.offset();
  s.next_id = r.u32("next body id");
  if (r.ok() && s.next_id == 0) return failed_at(next_id_at, "next body ID must be >= 1");
  const std::size_t def_at = r.offset();
  s.def = read_def(r);
  if (!r.ok()) return failed(r.error());
  if (auto e = check_world_def(s.def); !e.empty())
    return failed_at(def_at, "world definition: " + e);
  Rng::State rng{};
  const std::size_t rng_at = r.offset();
  for (std::uint64_t& word : rng)
    word = r.u64("rng state");
  if (r.ok() && !s.rng.set_state(rng)) return failed_at(rng_at, "rng state is all zero");

  const std::size_t set_count_at = r.offset();
  const std::uint32_t set_count = r.u32("property set count");
  if (r.ok() && set_count > r.remaining() / kMinPropertyBytes)
    return failed_at(set_count_at, "property set count " + std::to_string(set_count) +
                                       " exceeds what the data can hold");
  // Each set's bytes must differ from every other's.
  std::vector<Properties> sets;
  sets.reserve(set_count);
  std::unordered_set<std::string_view> seen;
  for (std::uint32_t i = 0; i < set_count && r.ok(); ++i) {
    const std::size_t at = r.offset();
    const Properties p = read_properties(r);
    if (!r.ok()) break;
    const std::string where = "property set " + std::to_string(i) + ": ";
    if (auto e = check_properties(p); !e.empty()) return failed_at(at, where + e);
    const std::string_view set_bytes(reinterpret_cast<const char*>(bytes.data() + at),
                                     r.offset() - at);
    if (!seen.insert(set_bytes).second) return failed_at(at, where + "the same as an earlier set");
    sets.push_back(p);
  }
  if (!r.ok()) return failed(r.error());

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
    set_properties(b, sets[set]);
    if (auto e = check_record(b); !e.empty()) return failed_at(at, where + e);
    s.bodies.push_back(b);
    previous_id = b.id.value;
  }
  if (!r.ok()) return failed(r.error());
  if (sets_used != set_count)
    return failed_at(set_count_at,
                     "property set " + std::to_string(sets_used) + " is used by no body");

  const std::size_t contact_count_at = r.offset();
  const std::uint32_t contact_count = r.u32("contact count");
  if (r.ok() && contact_count > r.remaining() / kMinContactBytes)
    return failed_at(contact_count_at, "contact count " + std::to_string(contact_count) +
                                           " exceeds what the data can hold");
  s.contacts.clear();
  s.contacts.reserve(contact_count);
  std::uint32_t previous_a = 0;
  for (std::uint32_t i = 0; i < contact_count && r.ok(); ++i) {
    const std::size_t at = r.offset();
    Contact c = read_contact(r, previous_a);
    if (!r.ok()) break;
    const std::string where =
        "contact (" + std::to_string(c.a) + ", " + std::to_string(c.b) + "): ";
    if (s.find(c.a) < 0 || s.find(c.b) < 0)
      return failed_at(at, where + "names a body that does not exist");
    if (!s.contacts.empty() && c.a == s.contacts.back().a && c.b <= s.contacts.back().b)
      return failed_at(at, where + "pairs must be unique and ascending");
    if (c.reported && !c.touching)
      return failed_at(at, where + "reported as touching without contact points");
    s.contacts.push_back(c);
    previous_a = c.a;
  }
  if (!r.ok()) return failed(r.error());
  if (!r.at_end())
    return failed_at(r.offset(),
                     std::to_string(r.remaining()) + " unexpected bytes after the state");
  return true;
}

}  // namespace

}  // namespace sim_detail

namespace sim_detail {
namespace {

/// The canonical bytes of the whole state (what save() returns) and where each part starts.
struct Encoded {
  ByteWriter w;
  std::size_t globals = 0, rng = 0, bodies = 0, contacts = 0;
};

void encode(const WorldState& s, Encoded& e) {
  e.w.reserve(256 + s.bodies.size() * 96 + s.contacts.size() * 72);
  e.w.u32(kMagic);
  e.w.u32(kVersion);
  e.globals = e.w.size();
  write_globals(s, e.w);
  e.rng = e.w.size();
  write_rng(s.rng, e.w);
  e.bodies = e.w.size();
  write_bodies(s, e.w);
  e.contacts = e.w.size();
  write_contacts(s, e.w);
}

}  // namespace
}  // namespace sim_detail

std::vector<std::uint8_t> World::save() const {
  sim_detail::Encoded e;
  sim_detail::encode(*s_, e);
  return e.w.take();
}

Status World::restore(std::span<const std::uint8_t> bytes) {
  auto scratch = std::make_unique<sim_detail::WorldState>();
  std::string error;
  if (!sim_detail::read_state(bytes, *scratch, error)) return Status::error(error);
  s_ = std::move(scratch);
  return Status::success();
}

StateHashes World::hashes() const {
  std::vector<std::uint8_t> bytes;
  return save(bytes);
}

StateHashes World::save(std::vector<std::uint8_t>& out) const {
  // One encoding: the total is the hash of save()'s bytes, each part the hash of its slice. The
  // bytes go into `out`'s own buffer, so a caller saving every frame allocates nothing.
  sim_detail::Encoded e{ByteWriter(std::move(out))};
  sim_detail::encode(*s_, e);
  const std::uint8_t* bytes = e.w.bytes().data();
  const auto slice = [&](std::size_t from, std::size_t to) {
    return hash64(std::span<const std::uint8_t>(bytes + from, to - from));
  };
  StateHashes h;
  h.globals = slice(e.globals, e.rng);
  h.rng = slice(e.rng, e.bodies);
  h.bodies = slice(e.bodies, e.contacts);
  h.contacts = slice(e.contacts, e.w.size());
  h.total = slice(0, e.w.size());
  out = e.w.take();
  return h;
}

Expected<std::uint64_t> World::body_hash(BodyId id) const {
  const std::ptrdiff_t i = s_->find(id.value);
  if (i < 0) return Status::error("no body with ID " + std::to_string(id.value));
  ByteWriter w;
  sim_detail::write_body(s_->bodies[static_cast<std::size_t>(i)], w);
  return sim_detail::xxh3(w.bytes());
}

}  // namespace detsim

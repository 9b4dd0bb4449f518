// The canonical state encoding (docs/STATE.md): save, restore and the hashes.
//
// Writer and reader of each part sit side by side so that a field added to one is seen missing
// from the other. Every integer is little-endian and of a fixed width; Fixed is its raw int64; bool
// is one byte 0/1; enums are one byte. The restore reads into a scratch WorldState and validates
// every field before the world is replaced, so bad bytes change nothing.
#include <xxhash.h>
#include <algorithm>

#include "world_state.hpp"

namespace detsim {

namespace sim_detail {

namespace {

constexpr std::uint32_t kMagic = 0x4D495344;  // "DSIM" read as little-endian bytes
constexpr std::uint32_t kVersion = state_encoding_version;

// Smallest encodings, to bound counts by the bytes that remain before allocating.
constexpr std::size_t kMinBodyBytes = 4 + 1 + 1 + 8 * 2 + 8 * 3;
constexpr std::size_t kMinContactBytes = 4 + 4 + 1 + 1;

std::uint64_t xxh3(const std::vector<std::uint8_t>& bytes) {
  return XXH3_64bits(bytes.data(), bytes.size());
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

void write_shape(const Shape& s, ByteWriter& w) {
  w.u8(static_cast<std::uint8_t>(s.type));
  switch (s.type) {
    case ShapeType::sphere:
      w.fixed(s.radius);
      break;
    case ShapeType::box:
      w.vec3(s.half_extents);
      break;
    case ShapeType::capsule:
      w.fixed(s.radius);
      w.fixed(s.half_height);
      break;
    case ShapeType::plane:
      break;
  }
}

Shape read_shape(ByteReader& r) {
  const std::uint8_t type = r.u8("shape type");
  switch (type) {
    case static_cast<std::uint8_t>(ShapeType::sphere):
      return Shape::sphere(r.fixed("sphere radius"));
    case static_cast<std::uint8_t>(ShapeType::box):
      return Shape::box(r.vec3("box half extents"));
    case static_cast<std::uint8_t>(ShapeType::capsule): {
      const Fixed radius = r.fixed("capsule radius");
      return Shape::capsule(radius, r.fixed("capsule half height"));
    }
    case static_cast<std::uint8_t>(ShapeType::plane):
      return Shape::plane();
    default:
      r.fail("shape type", "1 (sphere), 2 (box), 3 (capsule) or 4 (plane)");
      return {};
  }
}

BodyState read_body(ByteReader& r) {
  BodyState b;
  b.id = BodyId{r.u32("body id")};
  const std::uint8_t type = r.u8("body type");
  if (type > static_cast<std::uint8_t>(BodyType::dynamic))
    r.fail("body type", "0 (static), 1 (kinematic) or 2 (dynamic)");
  b.type = static_cast<BodyType>(type);
  b.shape = read_shape(r);
  b.position = r.vec3("body position");
  b.orientation = r.quat("body orientation");
  b.linear_velocity = r.vec3("body linear velocity");
  b.angular_velocity = r.vec3("body angular velocity");
  b.mass = r.fixed("body mass");
  b.inertia = r.vec3("body inertia");
  b.friction = r.fixed("body friction");
  b.restitution = r.fixed("body restitution");
  b.linear_damping = r.fixed("body linear damping");
  b.angular_damping = r.fixed("body angular damping");
  b.layer = r.u32("body layer");
  b.mask = r.u32("body mask");
  b.sensor = r.boolean("body sensor flag");
  b.ccd = r.boolean("body ccd flag");
  b.user_data = r.u64("body user data");
  b.awake = r.boolean("body awake flag");
  b.sleep_time = r.fixed("body sleep time");
  b.force = r.vec3("body force");
  b.torque = r.vec3("body torque");
  return b;
}

Contact read_contact(ByteReader& r) {
  Contact c;
  c.a = r.u32("contact body a");
  c.b = r.u32("contact body b");
  const std::size_t flags_at = r.offset();
  const std::uint8_t flags = r.u8("contact flags");
  if (flags > 3) r.fail_at(flags_at, "contact flags", "only bits 0 (touching) and 1 (reported)");
  c.touching = (flags & 1U) != 0;
  c.reported = (flags & 2U) != 0;
  c.point_count = r.u8("contact point count");
  if (c.point_count > 4) {
    r.fail("contact point count", "at most 4");
    return c;
  }
  for (std::size_t p = 0; p < c.point_count; ++p) {
    c.cached[p].feature = r.u32("contact feature");
    c.cached[p].normal_impulse = r.fixed("contact normal impulse");
    c.cached[p].tangent_impulse_1 = r.fixed("contact tangent impulse");
    c.cached[p].tangent_impulse_2 = r.fixed("contact tangent impulse");
  }
  return c;
}

// Semantic checks of a body read from bytes; "" when valid.
std::string check_body(const BodyState& b) {
  if (auto e = check_shape(b.shape, b.type); !e.empty()) return e;
  if (auto e = check_orientation(b.orientation); !e.empty()) return e;
  if (b.mass < Fixed::zero()) return "mass must be >= 0";
  if (b.type == BodyType::dynamic && (b.mass <= Fixed::zero() || b.inertia.x <= Fixed::zero() ||
                                      b.inertia.y <= Fixed::zero() || b.inertia.z <= Fixed::zero()))
    return "a dynamic body needs a positive mass and moments of inertia";
  if (b.friction < Fixed::zero() || b.restitution < Fixed::zero() || b.restitution > Fixed::one() ||
      b.linear_damping < Fixed::zero() || b.angular_damping < Fixed::zero() ||
      b.sleep_time < Fixed::zero())
    return "material or damping out of range";
  if (b.type == BodyType::static_body && b.awake) return "a static body cannot be awake";
  return {};
}

}  // namespace

void write_globals(const WorldState& s, ByteWriter& w) {
  w.u64(s.frame);
  w.u32(s.next_id);
  write_def(s.def, w);
}

void write_body(const BodyState& b, ByteWriter& w) {
  w.u32(b.id.value);
  w.u8(static_cast<std::uint8_t>(b.type));
  write_shape(b.shape, w);
  w.vec3(b.position);
  w.quat(b.orientation);
  w.vec3(b.linear_velocity);
  w.vec3(b.angular_velocity);
  w.fixed(b.mass);
  w.vec3(b.inertia);
  w.fixed(b.friction);
  w.fixed(b.restitution);
  w.fixed(b.linear_damping);
  w.fixed(b.angular_damping);
  w.u32(b.layer);
  w.u32(b.mask);
  w.boolean(b.sensor);
  w.boolean(b.ccd);
  w.u64(b.user_data);
  w.boolean(b.awake);
  w.fixed(b.sleep_time);
  w.vec3(b.force);
  w.vec3(b.torque);
}

void write_contact(const Contact& c, ByteWriter& w) {
  w.u32(c.a);
  w.u32(c.b);
  w.u8(static_cast<std::uint8_t>((c.touching ? 1U : 0U) | (c.reported ? 2U : 0U)));
  w.u8(c.point_count);
  for (std::size_t p = 0; p < c.point_count; ++p) {
    w.u32(c.cached[p].feature);
    w.fixed(c.cached[p].normal_impulse);
    w.fixed(c.cached[p].tangent_impulse_1);
    w.fixed(c.cached[p].tangent_impulse_2);
  }
}

namespace {

void write_rng(const Rng& rng, ByteWriter& w) {
  for (const std::uint64_t word : rng.state())
    w.u64(word);
}

void write_bodies(const WorldState& s, ByteWriter& w) {
  w.u32(static_cast<std::uint32_t>(s.bodies.size()));
  for (const BodyState& b : s.bodies)
    write_body(b, w);
}

void write_contacts(const WorldState& s, ByteWriter& w) {
  w.u32(static_cast<std::uint32_t>(s.contacts.size()));
  for (const Contact& c : s.contacts)
    write_contact(c, w);
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

  const std::size_t body_count_at = r.offset();
  const std::uint32_t body_count = r.u32("body count");
  if (r.ok() && body_count > r.remaining() / kMinBodyBytes)
    return failed_at(body_count_at, "body count " + std::to_string(body_count) +
                                        " exceeds what the data can hold");
  s.bodies.clear();
  s.bodies.reserve(body_count);
  for (std::uint32_t i = 0; i < body_count && r.ok(); ++i) {
    const std::size_t at = r.offset();
    BodyState b = read_body(r);
    if (!r.ok()) break;
    const std::string where = "body " + std::to_string(b.id.value) + ": ";
    if (b.id.value == 0 || b.id.value >= s.next_id)
      return failed_at(at, where + "ID must be in 1.." + std::to_string(s.next_id - 1));
    if (!s.bodies.empty() && b.id <= s.bodies.back().id)
      return failed_at(at, where + "IDs must be unique and ascending");
    if (auto e = check_body(b); !e.empty()) return failed_at(at, where + e);
    s.bodies.push_back(b);
  }
  if (!r.ok()) return failed(r.error());

  const std::size_t contact_count_at = r.offset();
  const std::uint32_t contact_count = r.u32("contact count");
  if (r.ok() && contact_count > r.remaining() / kMinContactBytes)
    return failed_at(contact_count_at, "contact count " + std::to_string(contact_count) +
                                           " exceeds what the data can hold");
  s.contacts.clear();
  s.contacts.reserve(contact_count);
  for (std::uint32_t i = 0; i < contact_count && r.ok(); ++i) {
    const std::size_t at = r.offset();
    Contact c = read_contact(r);
    if (!r.ok()) break;
    const std::string where =
        "contact (" + std::to_string(c.a) + ", " + std::to_string(c.b) + "): ";
    if (c.a >= c.b) return failed_at(at, where + "body IDs must be ascending within a pair");
    if (s.find(c.a) < 0 || s.find(c.b) < 0)
      return failed_at(at, where + "names a body that does not exist");
    if (!s.contacts.empty() &&
        (c.a < s.contacts.back().a || (c.a == s.contacts.back().a && c.b <= s.contacts.back().b)))
      return failed_at(at, where + "pairs must be unique and ascending");
    if (c.touching != (c.point_count > 0))
      return failed_at(at, where + "touching flag disagrees with the point count");
    if (c.reported && !c.touching)
      return failed_at(at, where + "reported as touching without contact points");
    s.contacts.push_back(c);
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
  e.w.reserve(64 + s.bodies.size() * 300 + s.contacts.size() * 64);
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
    return XXH3_64bits(bytes + from, to - from);
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

// An independent codec of the v6 world-state layout (docs/STATE.md), for the world-state tests
// (support/state_helpers.hpp includes it).
//
// Written from docs/STATE.md, not from state_io.cpp, so that the two can disagree. In brief:
//   "DSIM" u32 version=6 | var section count (7) | seven sections, each: var name length, name,
//   var section version (bodies 2, the others 1), u32 payload length, payload. The payloads, in
//   this order: globals: u64 frame | u32 next ID | definition (fixed width);  rng: 4 x u64;
//   geometry: var count, then per geometry u8 type (1 convex hull, 2 triangle mesh, 3 heightfield,
//   4 compound), u64 content hash;
//   bodies: u32 property-set count, sets in first-use order | u32 body count, bodies ascending by
//   ID;  contacts: u32 contact count, contacts ascending by (a, b);  joints: u32 next joint ID,
//   u32 joint count, joints ascending by ID;  particles: u32 next particle group ID, var group
//   count, groups ascending by ID (support/state_codec_particles.hpp).
// `var` is canonical LEB128 (at most 5 bytes for a 32-bit field, 10 for a 64-bit one); `vfixed` a
// var of the zigzag raw value. A set: type u8, shape (type u8, then its vfixed sizes, or a convex
// hull's, mesh's or heightfield's geometry ID var), mass, inertia, centre of mass (vec3), inertia
// axes (quat), friction, restitution, linear and angular damping (vfixed), layer u32, mask u32,
// flags u8 (sensor, CCD, then the locks: translation x, y, z, rotation x, y, z). A body: ID step
// var, set index var, flags u8 (awake, user data, force, torque follow), position, orientation,
// velocities, sleep time (vfixed), then the flagged values. A contact: a step var, b - a var, point
// byte (count in bits 0-2, reported in bit 3), then per point: feature on a, feature on b (var:
// index * 4 + kind), three impulses (vfixed). A joint: ID step var, type u8 (0-5), body a var, body
// b var, flags u8 (limit enabled, motor enabled, collide connected, broken, user data follows),
// anchor, axis (vec3), eleven definition numbers (vfixed), local anchors a and b, local axes a and
// b (vec3), relative orientation (quat), length (vfixed), linear and angular impulse (vec3), axial,
// motor and limit impulse (vfixed), then the user data.
//
// decode() is strict about what the layout itself says (canonical vars, enum values, flag bits,
// zero values flagged present, set order and use, ID and pair order, point bytes, features) and
// reports the first error with its byte offset; it does not repeat the simulation's own checks
// (unit quaternions, masses, the definition's ranges): it is a test oracle, not the validator.
// encode() writes the wire fields of a Decoded as they are, valid or not, so a test can decode a
// real state, change one field and re-encode.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/world.hpp>

#include "state_codec_particles.hpp"

namespace detsim::state_test {

using Bytes = std::vector<std::uint8_t>;

inline constexpr std::uint32_t kStateMagic = 0x4D495344U;
inline constexpr std::uint32_t kStateVersion = 6;
/// A World's sections, in their order, and their versions.
inline constexpr const char* kSectionNames[] = {"globals",  "rng",    "geometry", "bodies",
                                                "contacts", "joints", "particles"};
inline constexpr std::size_t kSectionCount = 7;
inline constexpr std::uint32_t kSectionVersions[] = {1, 1, 1, 2, 2, 1, 1};
// Each section's index in the lists above.
inline constexpr std::size_t kGlobals = 0;
inline constexpr std::size_t kRngSection = 1;
inline constexpr std::size_t kGeometry = 2;
inline constexpr std::size_t kBodies = 3;
inline constexpr std::size_t kContacts = 4;
inline constexpr std::size_t kJoints = 5;
inline constexpr std::size_t kParticles = 6;

// Body flags.
inline constexpr std::uint8_t kAwake = 1;
inline constexpr std::uint8_t kHasUserData = 2;
inline constexpr std::uint8_t kHasForce = 4;
inline constexpr std::uint8_t kHasTorque = 8;
// Property-set flags.
inline constexpr std::uint8_t kSensor = 1;
inline constexpr std::uint8_t kCcd = 2;
inline constexpr std::uint8_t kLockTranslationX = 4;  // then y 8, z 16, rotation x 32, y 64, z 128
// A contact's point byte.
inline constexpr std::uint8_t kPointCountBits = 7;
inline constexpr std::uint8_t kReported = 8;
inline constexpr std::uint8_t kSubShapes = 16;  // the contact's sub-shapes follow
// Joint flags.
inline constexpr std::uint8_t kLimitEnabled = 1;
inline constexpr std::uint8_t kMotorEnabled = 2;
inline constexpr std::uint8_t kCollideConnected = 4;
inline constexpr std::uint8_t kBroken = 8;
inline constexpr std::uint8_t kJointHasUserData = 16;

// The bytes of the world definition (fixed width) and the offsets of two of its fields.
inline constexpr std::size_t kDefinitionBytes = 137;
inline constexpr std::size_t kDtInDefinition = 24;
inline constexpr std::size_t kSubstepsInDefinition = 32;

// ---- Raw LEB128, for tests that craft (possibly non-canonical) vars ----

inline std::uint64_t zigzag(Fixed v) {
  const std::int64_t raw = v.raw();
  return (static_cast<std::uint64_t>(raw) << 1) ^ static_cast<std::uint64_t>(raw >> 63);
}

inline Fixed unzigzag(std::uint64_t z) {
  return Fixed::from_raw(static_cast<std::int64_t>((z >> 1) ^ (0 - (z & 1))));
}

/// LEB128 of `value` in at least `min_bytes` bytes: beyond the shortest form, continuation bytes
/// carrying zero groups are added, which makes an overlong (non-canonical) var.
inline Bytes leb128(std::uint64_t value, std::size_t min_bytes = 1) {
  Bytes out;
  do {
    out.push_back(static_cast<std::uint8_t>(value & 0x7FU));
    value >>= 7;
  } while (value != 0 || out.size() < min_bytes);
  for (std::size_t i = 0; i + 1 < out.size(); ++i)
    out[i] |= 0x80U;
  return out;
}

/// The length of the canonical var of `value`.
inline std::size_t var_size(std::uint64_t value) {
  return leb128(value).size();
}
inline std::size_t vfixed_size(Fixed v) {
  return var_size(zigzag(v));
}
inline std::size_t vec3_size(Vec3 v) {
  return vfixed_size(v.x) + vfixed_size(v.y) + vfixed_size(v.z);
}
inline std::size_t quat_size(Quat q) {
  return vfixed_size(q.w) + vfixed_size(q.x) + vfixed_size(q.y) + vfixed_size(q.z);
}

/// The length of the var (canonical or not) that starts at `at`.
inline std::size_t var_length_at(std::span<const std::uint8_t> bytes, std::size_t at) {
  std::size_t n = 0;
  while (at + n < bytes.size() && (bytes[at + n] & 0x80U) != 0)
    ++n;
  return n + 1;
}

/// Replaces the var that starts at `at` with the bytes `with` (what follows shifts).
inline void replace_var(Bytes& bytes, std::size_t at, std::span<const std::uint8_t> with) {
  const auto first = bytes.begin() + static_cast<std::ptrdiff_t>(at);
  bytes.erase(first, first + static_cast<std::ptrdiff_t>(var_length_at(bytes, at)));
  bytes.insert(bytes.begin() + static_cast<std::ptrdiff_t>(at), with.begin(), with.end());
}

inline void put_u32(Bytes& bytes, std::size_t at, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i)
    bytes[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

inline void put_i64(Bytes& bytes, std::size_t at, std::int64_t value) {
  const auto v = static_cast<std::uint64_t>(value);
  for (std::size_t i = 0; i < 8; ++i)
    bytes[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// ---- Features: the 16-bit feature (kind * 256 + index) and its wire form (index * 4 + kind) ----

inline std::uint64_t wire_feature(std::uint16_t feature) {
  return std::uint64_t{feature & 0xFFU} * 4 + (feature >> 8U);
}
inline std::uint16_t feature_of_wire(std::uint64_t wire) {
  return static_cast<std::uint16_t>(((wire & 3U) << 8U) | (wire >> 2U));
}

// ---- The decoded state ----

/// What bodies share. `type` and `shape.type` may hold any byte value (the enums have a fixed
/// underlying type); encode() then writes no shape payload for an unknown shape type.
struct DecodedSet {
  BodyType type = BodyType::dynamic;
  Shape shape{};
  Fixed mass{};
  Vec3 inertia{};
  Vec3 center_of_mass{};
  Quat inertia_axes{};
  Fixed friction{};
  Fixed restitution{};
  Fixed linear_damping{};
  Fixed angular_damping{};
  std::uint32_t layer = 1;
  std::uint32_t mask = 0xFFFFFFFFU;
  std::uint8_t flags = 0;  // kSensor, kCcd, the locks from kLockTranslationX
  // Filled by decode(), ignored by encode():
  std::size_t at = 0;
  std::size_t mass_at = 0;
  std::size_t end = 0;
};

inline bool same_properties(const DecodedSet& a, const DecodedSet& b) {
  return a.type == b.type && a.shape == b.shape && a.mass == b.mass && a.inertia == b.inertia &&
         a.center_of_mass == b.center_of_mass && a.inertia_axes == b.inertia_axes &&
         a.friction == b.friction && a.restitution == b.restitution &&
         a.linear_damping == b.linear_damping && a.angular_damping == b.angular_damping &&
         a.layer == b.layer && a.mask == b.mask && a.flags == b.flags;
}

struct DecodedBody {
  std::uint64_t id_step = 0;  // the ID minus the previous body's
  std::uint64_t set = 0;      // index into Decoded::sets
  std::uint8_t flags = 0;     // kAwake, kHasUserData, kHasForce, kHasTorque
  Vec3 position{};
  Quat orientation{};
  Vec3 linear_velocity{};
  Vec3 angular_velocity{};
  Fixed sleep_time{};
  // Written only when `flags` says so (and then whatever their value).
  std::uint64_t user_data = 0;
  Vec3 force{};
  Vec3 torque{};
  // Filled by decode(), ignored by encode():
  BodyId id{};
  std::size_t at = 0;  // the record, = its ID step
  std::size_t set_at = 0;
  std::size_t flags_at = 0;
  std::size_t position_at = 0;
  std::size_t orientation_at = 0;
  std::size_t linear_velocity_at = 0;
  std::size_t end = 0;
};

struct DecodedPoint {
  std::uint64_t feature_a = 0;  // wire form: index * 4 + kind
  std::uint64_t feature_b = 0;
  Fixed normal_impulse{};
  Fixed tangent_impulse_1{};
  Fixed tangent_impulse_2{};
  // Filled by decode(), ignored by encode():
  std::size_t at = 0;  // = feature on a
  std::size_t feature_b_at = 0;
  std::size_t normal_impulse_at = 0;
};

struct DecodedContact {
  std::uint64_t a_step = 0;     // a minus the previous contact's a
  std::uint64_t b_minus_a = 0;  // b minus a, at least 1
  std::uint8_t points_byte = 0;
  std::uint64_t sub_a = 0;  // written when points_byte has kSubShapes
  std::uint64_t sub_b = 0;
  std::vector<DecodedPoint> points;  // encode() writes all of them, whatever points_byte says
  // Filled by decode(), ignored by encode():
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  std::size_t at = 0;  // the record, = its a step
  std::size_t b_at = 0;
  std::size_t points_at = 0;  // the point byte
  std::size_t end = 0;

  [[nodiscard]] unsigned point_count() const { return points_byte & kPointCountBits; }
  [[nodiscard]] bool reported() const { return (points_byte & kReported) != 0; }
};

struct DecodedJoint {
  std::uint64_t id_step = 0;  // the ID minus the previous joint's
  std::uint8_t type = 0;      // JointType's value (any byte)
  std::uint64_t body_a = 0;
  std::uint64_t body_b = 0;
  std::uint8_t flags = 0;  // kLimitEnabled, kMotorEnabled, kCollideConnected, kBroken, user data
  Vec3 anchor{};
  Vec3 axis{};
  // limit lower, limit upper, swing limit, motor speed, motor max force, min length, max length,
  // spring frequency, spring damping ratio, break force, break torque.
  std::array<Fixed, 11> numbers{};
  Vec3 local_anchor_a{};
  Vec3 local_anchor_b{};
  Vec3 local_axis_a{};
  Vec3 local_axis_b{};
  Quat relative_orientation{};
  Fixed length{};
  Vec3 linear_impulse{};
  Vec3 angular_impulse{};
  Fixed axial_impulse{};
  Fixed motor_impulse{};
  Fixed limit_impulse{};
  std::uint64_t user_data = 0;  // written only when `flags` says so
  // Filled by decode(), ignored by encode():
  std::uint32_t id = 0;
  std::size_t at = 0;  // the record, = its ID step
  std::size_t type_at = 0;
  std::size_t body_a_at = 0;
  std::size_t flags_at = 0;
  std::size_t axis_at = 0;
  std::size_t numbers_at = 0;
  std::size_t local_axis_a_at = 0;
  std::size_t relative_orientation_at = 0;
  std::size_t length_at = 0;
  std::size_t end = 0;
};

/// A geometry entry: its type byte and content hash.
struct DecodedGeometry {
  std::uint8_t type = 1;
  std::uint64_t hash = 0;
  std::size_t at = 0;  // filled by decode()
};

struct Decoded {
  bool ok = false;
  std::string error;  // "byte N: what", the first error
  std::uint32_t magic = kStateMagic;
  std::uint32_t version = kStateVersion;
  std::uint64_t frame = 0;
  std::uint32_t next_id = 1;
  WorldDef def;
  Rng::State rng{};
  std::vector<DecodedGeometry> geometries;
  std::vector<DecodedSet> sets;
  std::vector<DecodedBody> bodies;
  std::vector<DecodedContact> contacts;
  std::uint32_t next_joint_id = 1;
  std::vector<DecodedJoint> joints;
  DecodedParticles particles;  // next group ID, groups (and their offsets)
  // Offsets, filled by decode(): of each section's record (its name length), its u32 payload
  // length and its payload, in kSectionNames' order; then of the payloads' fields.
  std::array<std::size_t, kSectionCount> section_at{};
  std::array<std::size_t, kSectionCount> section_length_at{};
  std::array<std::size_t, kSectionCount> payload_at{};
  std::size_t globals_at = 0;  // the frame
  std::size_t next_id_at = 0;
  std::size_t def_at = 0;
  std::size_t rng_at = 0;
  std::size_t geometry_count_at = 0;
  std::size_t property_count_at = 0;
  std::size_t body_count_at = 0;
  std::size_t contact_count_at = 0;
  std::size_t next_joint_id_at = 0;
  std::size_t joint_count_at = 0;
  std::size_t end = 0;
};

// ---- Reading ----

class StateReader {
 public:
  explicit StateReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}

  [[nodiscard]] bool ok() const { return error_.empty(); }
  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] std::size_t at() const { return at_; }
  [[nodiscard]] bool at_end() const { return at_ == bytes_.size(); }
  [[nodiscard]] std::size_t remaining() const { return bytes_.size() - at_; }

  /// Records the first error only.
  void fail(std::size_t at, const std::string& what) {
    if (ok()) error_ = "byte " + std::to_string(at) + ": " + what;
  }

  std::uint8_t u8(const char* what) { return static_cast<std::uint8_t>(little_endian(1, what)); }
  std::uint32_t u32(const char* what) { return static_cast<std::uint32_t>(little_endian(4, what)); }
  std::uint64_t u64(const char* what) { return little_endian(8, what); }
  Fixed fixed(const char* what) {
    return Fixed::from_raw(static_cast<std::int64_t>(little_endian(8, what)));
  }
  bool boolean(const char* what) {
    const std::size_t start = at_;
    const std::uint8_t v = u8(what);
    if (v > 1) fail(start, std::string(what) + ": not 0 or 1");
    return v == 1;
  }

  /// A canonical LEB128 var of a `bits`-bit field (32 or 64).
  std::uint64_t var(const char* what, unsigned bits) {
    if (!ok()) return 0;
    const std::size_t start = at_;
    const std::size_t max_bytes = bits == 32 ? 5 : 10;
    std::uint64_t value = 0;
    for (std::size_t i = 0;; ++i) {
      if (i == max_bytes) {
        fail(start,
             std::string(what) + ": a var longer than " + std::to_string(max_bytes) + " bytes");
        return 0;
      }
      if (at_ == bytes_.size()) {
        fail(start, std::string(what) + ": the data ends inside a var");
        return 0;
      }
      const std::uint8_t byte = bytes_[at_++];
      const std::uint64_t group = byte & 0x7FU;
      if (i == 9 && group > 1) {
        fail(start, std::string(what) + ": a var beyond 64 bits");
        return 0;
      }
      value |= group << (7 * i);
      if ((byte & 0x80U) == 0) {
        if (byte == 0 && i > 0) fail(start, std::string(what) + ": an overlong var");
        break;
      }
    }
    if (bits == 32 && value > 0xFFFFFFFFU)
      fail(start, std::string(what) + ": a var beyond 32 bits");
    return ok() ? value : 0;
  }
  Fixed vfixed(const char* what) { return unzigzag(var(what, 64)); }
  Vec3 vvec3(const char* what) {
    const Fixed x = vfixed(what);
    const Fixed y = vfixed(what);
    return {x, y, vfixed(what)};
  }
  Quat vquat(const char* what) {
    const Fixed w = vfixed(what);
    const Fixed x = vfixed(what);
    const Fixed y = vfixed(what);
    return {w, x, y, vfixed(what)};
  }

 private:
  std::uint64_t little_endian(std::size_t n, const char* what) {
    if (!ok()) return 0;
    if (bytes_.size() - at_ < n) {
      fail(at_, std::string(what) + ": the data ends here");
      return 0;
    }
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < n; ++i)
      v |= std::uint64_t{bytes_[at_ + i]} << (8 * i);
    at_ += n;
    return v;
  }

  std::span<const std::uint8_t> bytes_;
  std::size_t at_ = 0;
  std::string error_;
};

inline WorldDef read_definition(StateReader& r) {
  WorldDef def;
  const Fixed gx = r.fixed("gravity");
  const Fixed gy = r.fixed("gravity");
  def.gravity = {gx, gy, r.fixed("gravity")};
  def.dt = r.fixed("dt");
  def.substeps = r.u32("substeps");
  def.iterations = r.u32("iterations");
  def.seed = r.u64("seed");
  def.max_linear_speed = r.fixed("max linear speed");
  def.max_angular_speed = r.fixed("max angular speed");
  def.contact_hertz = r.fixed("contact hertz");
  def.contact_damping_ratio = r.fixed("contact damping ratio");
  def.contact_push_max = r.fixed("contact push max");
  def.restitution_threshold = r.fixed("restitution threshold");
  def.linear_slop = r.fixed("linear slop");
  def.speculative_distance = r.fixed("speculative distance");
  def.enable_sleep = r.boolean("enable sleep");
  def.sleep_linear_speed = r.fixed("sleep linear speed");
  def.sleep_angular_speed = r.fixed("sleep angular speed");
  def.time_to_sleep = r.fixed("time to sleep");
  return def;
}

inline DecodedSet read_set(StateReader& r) {
  DecodedSet s;
  s.at = r.at();
  const std::uint8_t type = r.u8("set type");
  if (type > 2) r.fail(s.at, "set type: not 0, 1 or 2");
  s.type = static_cast<BodyType>(type);
  const std::size_t shape_at = r.at();
  s.shape.type = static_cast<ShapeType>(r.u8("shape type"));
  switch (s.shape.type) {
    case ShapeType::sphere:
      s.shape.radius = r.vfixed("radius");
      break;
    case ShapeType::box:
      s.shape.half_extents = r.vvec3("half extents");
      break;
    case ShapeType::capsule:
    case ShapeType::cylinder:
      s.shape.radius = r.vfixed("radius");
      s.shape.half_height = r.vfixed("half height");
      break;
    case ShapeType::plane:
      break;
    case ShapeType::convex:
    case ShapeType::mesh:
    case ShapeType::heightfield:
    case ShapeType::compound:
      s.shape.geometry = GeometryId{static_cast<std::uint32_t>(r.var("geometry ID", 32))};
      break;
    default:
      r.fail(shape_at, "shape type: not 1 to 9");
  }
  s.mass_at = r.at();
  s.mass = r.vfixed("mass");
  s.inertia = r.vvec3("inertia");
  s.center_of_mass = r.vvec3("centre of mass");
  s.inertia_axes = r.vquat("inertia axes");
  s.friction = r.vfixed("friction");
  s.restitution = r.vfixed("restitution");
  s.linear_damping = r.vfixed("linear damping");
  s.angular_damping = r.vfixed("angular damping");
  s.layer = r.u32("layer");
  s.mask = r.u32("mask");
  const std::size_t flags_at = r.at();
  s.flags = r.u8("set flags");
  (void)flags_at;  // every bit has a meaning: sensor, CCD and the six locks
  s.end = r.at();
  return s;
}

inline void read_body(StateReader& r, Decoded& d, std::uint64_t& previous_id, std::size_t& used) {
  DecodedBody b;
  b.at = r.at();
  b.id_step = r.var("body ID step", 32);
  if (r.ok() && b.id_step == 0) r.fail(b.at, "body ID step: zero");
  const std::uint64_t id = previous_id + b.id_step;
  if (r.ok() && id >= d.next_id) r.fail(b.at, "body ID: not below the next ID");
  previous_id = id;
  b.id = BodyId{static_cast<std::uint32_t>(id)};
  b.set_at = r.at();
  b.set = r.var("property set", 32);
  if (r.ok() && b.set >= d.sets.size()) r.fail(b.set_at, "property set: out of range");
  if (r.ok() && b.set > used) r.fail(b.set_at, "property set: not in first-use order");
  if (r.ok() && b.set == used) ++used;
  b.flags_at = r.at();
  b.flags = r.u8("body flags");
  if ((b.flags & ~(kAwake | kHasUserData | kHasForce | kHasTorque)) != 0)
    r.fail(b.flags_at, "body flags: an unknown bit");
  if (r.ok() && (b.flags & kAwake) != 0 &&
      d.sets[static_cast<std::size_t>(b.set)].type == BodyType::static_body)
    r.fail(b.flags_at, "body flags: a static body is awake");
  b.position_at = r.at();
  b.position = r.vvec3("position");
  b.orientation_at = r.at();
  b.orientation = r.vquat("orientation");
  b.linear_velocity_at = r.at();
  b.linear_velocity = r.vvec3("linear velocity");
  b.angular_velocity = r.vvec3("angular velocity");
  b.sleep_time = r.vfixed("sleep time");
  if ((b.flags & kHasUserData) != 0) {
    const std::size_t at = r.at();
    b.user_data = r.var("user data", 64);
    if (r.ok() && b.user_data == 0) r.fail(at, "user data: flagged present but zero");
  }
  if ((b.flags & kHasForce) != 0) {
    const std::size_t at = r.at();
    b.force = r.vvec3("force");
    if (r.ok() && b.force == Vec3{}) r.fail(at, "force: flagged present but zero");
  }
  if ((b.flags & kHasTorque) != 0) {
    const std::size_t at = r.at();
    b.torque = r.vvec3("torque");
    if (r.ok() && b.torque == Vec3{}) r.fail(at, "torque: flagged present but zero");
  }
  b.end = r.at();
  d.bodies.push_back(b);
}

inline bool has_body(const Decoded& d, std::uint64_t id) {
  const auto it = std::lower_bound(
      d.bodies.begin(), d.bodies.end(), id,
      [](const DecodedBody& b, std::uint64_t value) { return b.id.value < value; });
  return it != d.bodies.end() && it->id.value == id;
}

inline void read_contact(StateReader& r, Decoded& d, std::uint64_t& previous_a,
                         std::uint64_t& previous_b, std::uint64_t& previous_sub_a,
                         std::uint64_t& previous_sub_b) {
  DecodedContact c;
  c.at = r.at();
  c.a_step = r.var("contact a step", 32);
  c.b_at = r.at();
  c.b_minus_a = r.var("contact b - a", 32);
  const std::uint64_t a = previous_a + c.a_step;
  const std::uint64_t b = a + c.b_minus_a;
  if (r.ok() && c.b_minus_a == 0) r.fail(c.b_at, "contact b - a: zero");
  if (r.ok() && (!has_body(d, a) || !has_body(d, b))) r.fail(c.at, "contact: no such body");
  c.a = static_cast<std::uint32_t>(a);
  c.b = static_cast<std::uint32_t>(b);
  c.points_at = r.at();
  c.points_byte = r.u8("contact points");
  if ((c.points_byte & ~(kPointCountBits | kReported | kSubShapes)) != 0)
    r.fail(c.points_at, "contact points: an unknown bit");
  if ((c.points_byte & kSubShapes) != 0) {
    c.sub_a = r.var("contact sub-shape a", 32);
    c.sub_b = r.var("contact sub-shape b", 32);
    if (r.ok() && c.sub_a == 0 && c.sub_b == 0) r.fail(c.points_at, "contact sub-shapes: both 0");
  }
  // Ascending (a, b, sub_a, sub_b), each once.
  const auto key = [](std::uint64_t x, std::uint64_t y, std::uint64_t u, std::uint64_t v) {
    return std::array<std::uint64_t, 4>{x, y, u, v};
  };
  if (r.ok() && !d.contacts.empty() &&
      key(a, b, c.sub_a, c.sub_b) <= key(previous_a, previous_b, previous_sub_a, previous_sub_b))
    r.fail(c.at, "contact: not in ascending (a, b, sub_a, sub_b) order");
  previous_a = a;
  previous_b = b;
  previous_sub_a = c.sub_a;
  previous_sub_b = c.sub_b;
  if (c.point_count() > 4) r.fail(c.points_at, "contact points: more than four");
  if (c.reported() && c.point_count() == 0)
    r.fail(c.points_at, "contact points: reported without points");
  for (unsigned p = 0; p < c.point_count() && r.ok(); ++p) {
    DecodedPoint point;
    point.at = r.at();
    point.feature_a = r.var("feature on a", 32);
    if (point.feature_a > 65535) r.fail(point.at, "feature on a: beyond 65535");
    point.feature_b_at = r.at();
    point.feature_b = r.var("feature on b", 32);
    if (point.feature_b > 65535) r.fail(point.feature_b_at, "feature on b: beyond 65535");
    point.normal_impulse_at = r.at();
    point.normal_impulse = r.vfixed("normal impulse");
    point.tangent_impulse_1 = r.vfixed("tangent impulse 1");
    point.tangent_impulse_2 = r.vfixed("tangent impulse 2");
    c.points.push_back(point);
  }
  c.end = r.at();
  d.contacts.push_back(c);
}

inline void read_joint(StateReader& r, Decoded& d, std::uint64_t& previous_id) {
  DecodedJoint j;
  j.at = r.at();
  j.id_step = r.var("joint ID step", 32);
  if (r.ok() && j.id_step == 0) r.fail(j.at, "joint ID step: zero");
  const std::uint64_t id = previous_id + j.id_step;
  if (r.ok() && id >= d.next_joint_id) r.fail(j.at, "joint ID: not below the next joint ID");
  previous_id = id;
  j.id = static_cast<std::uint32_t>(id);
  j.type_at = r.at();
  j.type = r.u8("joint type");
  if (r.ok() && j.type > 5) r.fail(j.type_at, "joint type: not 0 to 5");
  j.body_a_at = r.at();
  j.body_a = r.var("joint body a", 32);
  j.body_b = r.var("joint body b", 32);
  j.flags_at = r.at();
  j.flags = r.u8("joint flags");
  if (r.ok() && j.flags >= 32) r.fail(j.flags_at, "joint flags: an unknown bit");
  j.anchor = r.vvec3("joint anchor");
  j.axis_at = r.at();
  j.axis = r.vvec3("joint axis");
  j.numbers_at = r.at();
  for (Fixed& f : j.numbers)
    f = r.vfixed("joint definition number");
  j.local_anchor_a = r.vvec3("local anchor a");
  j.local_anchor_b = r.vvec3("local anchor b");
  j.local_axis_a_at = r.at();
  j.local_axis_a = r.vvec3("local axis a");
  j.local_axis_b = r.vvec3("local axis b");
  j.relative_orientation_at = r.at();
  j.relative_orientation = r.vquat("relative orientation");
  j.length_at = r.at();
  j.length = r.vfixed("length");
  j.linear_impulse = r.vvec3("linear impulse");
  j.angular_impulse = r.vvec3("angular impulse");
  j.axial_impulse = r.vfixed("axial impulse");
  j.motor_impulse = r.vfixed("motor impulse");
  j.limit_impulse = r.vfixed("limit impulse");
  if ((j.flags & kJointHasUserData) != 0) {
    const std::size_t at = r.at();
    j.user_data = r.var("joint user data", 64);
    if (r.ok() && j.user_data == 0) r.fail(at, "joint user data: flagged present but zero");
  }
  j.end = r.at();
  d.joints.push_back(j);
}

/// Decodes a whole v6 state; `ok` is false and `error` names the first problem otherwise (what was
/// decoded up to there is kept).
inline Decoded decode(std::span<const std::uint8_t> bytes) {
  Decoded d;
  StateReader r(bytes);
  d.magic = r.u32("magic");
  if (r.ok() && d.magic != kStateMagic) r.fail(0, "magic");
  d.version = r.u32("version");
  if (r.ok() && d.version != kStateVersion) r.fail(4, "version");
  const std::size_t count_at = r.at();
  const std::uint64_t sections = r.var("section count", 64);
  if (r.ok() && sections != kSectionCount) r.fail(count_at, "section count: not 7");
  for (std::size_t i = 0; i < kSectionCount && r.ok(); ++i) {
    // The section's record: its name, its version, its payload's length; the payload must end
    // exactly where the length says.
    d.section_at[i] = r.at();
    const std::uint64_t name_size = r.var("section name length", 64);
    std::string name;
    for (std::uint64_t k = 0; k < name_size && r.ok() && k < 64; ++k)
      name += static_cast<char>(r.u8("section name"));
    if (r.ok() && name != kSectionNames[i])
      r.fail(d.section_at[i], std::string("section name: not ") + kSectionNames[i]);
    const std::size_t version_at = r.at();
    if (r.var("section version", 32) != kSectionVersions[i] && r.ok())
      r.fail(version_at, "section version");
    d.section_length_at[i] = r.at();
    const std::uint32_t length = r.u32("section length");
    d.payload_at[i] = r.at();
    if (!r.ok()) break;
    switch (i) {
      case 0:
        d.globals_at = r.at();
        d.frame = r.u64("frame");
        d.next_id_at = r.at();
        d.next_id = r.u32("next ID");
        d.def_at = r.at();
        d.def = read_definition(r);
        break;
      case 1:
        d.rng_at = r.at();
        for (std::uint64_t& word : d.rng)
          word = r.u64("rng");
        break;
      case kGeometry: {
        d.geometry_count_at = r.at();
        const std::uint64_t count = r.var("geometry count", 64);
        for (std::uint64_t k = 0; k < count && r.ok(); ++k) {
          DecodedGeometry g;
          g.at = r.at();
          g.type = r.u8("geometry type");
          if (r.ok() && (g.type < 1 || g.type > 4)) r.fail(g.at, "geometry type: not 1 to 4");
          g.hash = r.u64("geometry hash");
          d.geometries.push_back(g);
        }
        break;
      }
      case kBodies: {
        d.property_count_at = r.at();
        const std::uint32_t set_count = r.u32("property-set count");
        for (std::uint32_t k = 0; k < set_count && r.ok(); ++k) {
          const DecodedSet s = read_set(r);
          for (const DecodedSet& other : d.sets) {
            if (r.ok() && same_properties(s, other)) r.fail(s.at, "property set: a duplicate");
          }
          d.sets.push_back(s);
        }
        d.body_count_at = r.at();
        const std::uint32_t body_count = r.u32("body count");
        std::uint64_t previous_id = 0;
        std::size_t used = 0;
        for (std::uint32_t k = 0; k < body_count && r.ok(); ++k)
          read_body(r, d, previous_id, used);
        if (r.ok() && used != d.sets.size()) r.fail(d.property_count_at, "property set: unused");
        break;
      }
      case kJoints: {
        d.next_joint_id_at = r.at();
        d.next_joint_id = r.u32("next joint ID");
        if (r.ok() && d.next_joint_id == 0) r.fail(d.next_joint_id_at, "next joint ID: zero");
        d.joint_count_at = r.at();
        const std::uint32_t joint_count = r.u32("joint count");
        std::uint64_t previous_id = 0;
        for (std::uint32_t k = 0; k < joint_count && r.ok(); ++k)
          read_joint(r, d, previous_id);
        break;
      }
      case kParticles:
        read_particles_section(r, d.particles);
        break;
      default: {
        d.contact_count_at = r.at();
        const std::uint32_t contact_count = r.u32("contact count");
        std::uint64_t previous_a = 0;
        std::uint64_t previous_b = 0;
        std::uint64_t previous_sub_a = 0;
        std::uint64_t previous_sub_b = 0;
        for (std::uint32_t k = 0; k < contact_count && r.ok(); ++k)
          read_contact(r, d, previous_a, previous_b, previous_sub_a, previous_sub_b);
        break;
      }
    }
    if (r.ok() && r.at() != d.payload_at[i] + length)
      r.fail(d.section_length_at[i], "section length: not where the payload ends");
  }

  d.end = r.at();
  if (r.ok() && !r.at_end()) r.fail(r.at(), "trailing bytes");
  d.ok = r.ok();
  d.error = r.error();
  return d;
}

// ---- Writing ----

class StateWriter {
 public:
  void u8(std::uint8_t v) { bytes_.push_back(v); }
  void u32(std::uint32_t v) { little_endian(v, 4); }
  void u64(std::uint64_t v) { little_endian(v, 8); }
  void fixed(Fixed v) { little_endian(static_cast<std::uint64_t>(v.raw()), 8); }
  void var(std::uint64_t v) {
    const Bytes b = leb128(v);
    bytes_.insert(bytes_.end(), b.begin(), b.end());
  }
  void vfixed(Fixed v) { var(zigzag(v)); }
  void vvec3(Vec3 v) {
    vfixed(v.x);
    vfixed(v.y);
    vfixed(v.z);
  }
  void vquat(Quat q) {
    vfixed(q.w);
    vfixed(q.x);
    vfixed(q.y);
    vfixed(q.z);
  }
  [[nodiscard]] Bytes take() { return std::move(bytes_); }

 private:
  void little_endian(std::uint64_t v, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i)
      bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  Bytes bytes_;
};

inline void write_set(StateWriter& w, const DecodedSet& s) {
  w.u8(static_cast<std::uint8_t>(s.type));
  w.u8(static_cast<std::uint8_t>(s.shape.type));
  switch (s.shape.type) {
    case ShapeType::sphere:
      w.vfixed(s.shape.radius);
      break;
    case ShapeType::box:
      w.vvec3(s.shape.half_extents);
      break;
    case ShapeType::capsule:
    case ShapeType::cylinder:
      w.vfixed(s.shape.radius);
      w.vfixed(s.shape.half_height);
      break;
    case ShapeType::convex:
    case ShapeType::compound:
      w.var(s.shape.geometry.value);
      break;
    default:
      break;
  }
  w.vfixed(s.mass);
  w.vvec3(s.inertia);
  w.vvec3(s.center_of_mass);
  w.vquat(s.inertia_axes);
  w.vfixed(s.friction);
  w.vfixed(s.restitution);
  w.vfixed(s.linear_damping);
  w.vfixed(s.angular_damping);
  w.u32(s.layer);
  w.u32(s.mask);
  w.u8(s.flags);
}

inline void write_body(StateWriter& w, const DecodedBody& b) {
  w.var(b.id_step);
  w.var(b.set);
  w.u8(b.flags);
  w.vvec3(b.position);
  w.vquat(b.orientation);
  w.vvec3(b.linear_velocity);
  w.vvec3(b.angular_velocity);
  w.vfixed(b.sleep_time);
  if ((b.flags & kHasUserData) != 0) w.var(b.user_data);
  if ((b.flags & kHasForce) != 0) w.vvec3(b.force);
  if ((b.flags & kHasTorque) != 0) w.vvec3(b.torque);
}

inline void write_contact(StateWriter& w, const DecodedContact& c) {
  w.var(c.a_step);
  w.var(c.b_minus_a);
  w.u8(c.points_byte);
  if ((c.points_byte & kSubShapes) != 0) {
    w.var(c.sub_a);
    w.var(c.sub_b);
  }
  for (const DecodedPoint& p : c.points) {
    w.var(p.feature_a);
    w.var(p.feature_b);
    w.vfixed(p.normal_impulse);
    w.vfixed(p.tangent_impulse_1);
    w.vfixed(p.tangent_impulse_2);
  }
}

inline void write_joint(StateWriter& w, const DecodedJoint& j) {
  w.var(j.id_step);
  w.u8(j.type);
  w.var(j.body_a);
  w.var(j.body_b);
  w.u8(j.flags);
  w.vvec3(j.anchor);
  w.vvec3(j.axis);
  for (const Fixed f : j.numbers)
    w.vfixed(f);
  w.vvec3(j.local_anchor_a);
  w.vvec3(j.local_anchor_b);
  w.vvec3(j.local_axis_a);
  w.vvec3(j.local_axis_b);
  w.vquat(j.relative_orientation);
  w.vfixed(j.length);
  w.vvec3(j.linear_impulse);
  w.vvec3(j.angular_impulse);
  w.vfixed(j.axial_impulse);
  w.vfixed(j.motor_impulse);
  w.vfixed(j.limit_impulse);
  if ((j.flags & kJointHasUserData) != 0) w.var(j.user_data);
}

/// The v6 bytes of `d`'s wire fields (the offsets and derived IDs are ignored; the counts are the
/// sizes of the vectors, the section lengths those of the payloads written).
inline Bytes encode(const Decoded& d) {
  StateWriter payloads[kSectionCount];
  StateWriter& globals = payloads[0];
  globals.u64(d.frame);
  globals.u32(d.next_id);
  const WorldDef& def = d.def;
  globals.fixed(def.gravity.x);
  globals.fixed(def.gravity.y);
  globals.fixed(def.gravity.z);
  globals.fixed(def.dt);
  globals.u32(def.substeps);
  globals.u32(def.iterations);
  globals.u64(def.seed);
  for (const Fixed f :
       {def.max_linear_speed, def.max_angular_speed, def.contact_hertz, def.contact_damping_ratio,
        def.contact_push_max, def.restitution_threshold, def.linear_slop, def.speculative_distance})
    globals.fixed(f);
  globals.u8(def.enable_sleep ? 1 : 0);
  globals.fixed(def.sleep_linear_speed);
  globals.fixed(def.sleep_angular_speed);
  globals.fixed(def.time_to_sleep);
  for (const std::uint64_t word : d.rng)
    payloads[kRngSection].u64(word);
  payloads[kGeometry].var(d.geometries.size());
  for (const DecodedGeometry& g : d.geometries) {
    payloads[kGeometry].u8(g.type);
    payloads[kGeometry].u64(g.hash);
  }
  payloads[kBodies].u32(static_cast<std::uint32_t>(d.sets.size()));
  for (const DecodedSet& s : d.sets)
    write_set(payloads[kBodies], s);
  payloads[kBodies].u32(static_cast<std::uint32_t>(d.bodies.size()));
  for (const DecodedBody& b : d.bodies)
    write_body(payloads[kBodies], b);
  payloads[kContacts].u32(static_cast<std::uint32_t>(d.contacts.size()));
  for (const DecodedContact& c : d.contacts)
    write_contact(payloads[kContacts], c);
  payloads[kJoints].u32(d.next_joint_id);
  payloads[kJoints].u32(static_cast<std::uint32_t>(d.joints.size()));
  for (const DecodedJoint& j : d.joints)
    write_joint(payloads[kJoints], j);
  write_particles_section(payloads[kParticles], d.particles);

  StateWriter w;
  w.u32(d.magic);
  w.u32(d.version);
  w.var(kSectionCount);
  for (std::size_t i = 0; i < kSectionCount; ++i) {
    const std::string name = kSectionNames[i];
    w.var(name.size());
    for (const char c : name)
      w.u8(static_cast<std::uint8_t>(c));
    w.var(kSectionVersions[i]);
    const Bytes payload = payloads[i].take();
    w.u32(static_cast<std::uint32_t>(payload.size()));
    for (const std::uint8_t b : payload)
      w.u8(b);
  }
  return w.take();
}

/// After a test changed the length of a payload in place (a var made longer, bytes cut), the
/// section lengths that `before` (decoded from the bytes before the change) recorded, adjusted by
/// `delta` bytes for the section that holds byte `at`.
inline void adjust_section_length(Bytes& bytes, const Decoded& before, std::size_t at,
                                  std::ptrdiff_t delta) {
  for (std::size_t i = kSectionCount; i-- > 0;) {
    if (at < before.payload_at[i]) continue;
    const std::size_t length_at = before.section_length_at[i];
    std::uint32_t length = 0;
    for (std::size_t k = 0; k < 4; ++k)
      length |= static_cast<std::uint32_t>(bytes[length_at + k]) << (8 * k);
    put_u32(bytes, length_at,
            static_cast<std::uint32_t>(static_cast<std::ptrdiff_t>(length) + delta));
    return;
  }
}

inline Bytes encode_set(const DecodedSet& s) {
  StateWriter w;
  write_set(w, s);
  return w.take();
}

inline Bytes encode_body(const DecodedBody& b) {
  StateWriter w;
  write_body(w, b);
  return w.take();
}

}  // namespace detsim::state_test

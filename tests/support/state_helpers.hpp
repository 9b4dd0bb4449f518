// Shared helpers of the world-state tests (sim_state_test.cpp, sim_state_restore_test.cpp): scenes
// built through the public API, an independent reader of the v1 state layout, byte patching, and
// the check that a refused restore changes nothing.
//
// It also replaces the global operator new with one that records the largest request (rule 7:
// sizes are validated before allocating), so include it from one file of a test executable only.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <new>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#define XXH_INLINE_ALL
#include <xxhash.h>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>
#include <detsim/sim/bytes.hpp>
#include <detsim/sim/world.hpp>

#include "support/vector_print.hpp"

// ---- Allocation probe ----
//
// Rule 7 says "validate sizes before allocating": a hostile count in a few bytes must not turn into
// a huge allocation. The replaceable global operator new records the largest single request so a
// test can bound it (it forwards to malloc, which the sanitizers still watch).
inline std::atomic<std::size_t> g_largest_allocation{0};

// Not inlined: GCC would otherwise see free() called on memory from operator new at the call
// sites and warn (-Wmismatched-new-delete), although the pair is consistent.
[[gnu::noinline]] void* operator new(std::size_t size) {
  std::size_t seen = g_largest_allocation.load(std::memory_order_relaxed);
  while (size > seen &&
         !g_largest_allocation.compare_exchange_weak(seen, size, std::memory_order_relaxed)) {
  }
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
[[gnu::noinline]] void operator delete(void* p) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}

namespace detsim {

inline void PrintTo(const StateHashes& h, std::ostream* os) {
  *os << std::hex << "{total 0x" << h.total << ", globals 0x" << h.globals << ", rng 0x" << h.rng
      << ", bodies 0x" << h.bodies << ", contacts 0x" << h.contacts << "}" << std::dec;
}

namespace state_test {

using namespace detsim::literals;
using Bytes = std::vector<std::uint8_t>;

// ---- Scenes, built through the public API ----

inline BodyId add(World& w, const BodyDef& def) {
  const Expected<BodyId> id = w.create_body(def);
  EXPECT_TRUE(id.ok()) << id.message();
  return id.ok() ? id.value() : BodyId{};
}

inline World make_world(const WorldDef& def) {
  Expected<World> w = World::create(def);
  EXPECT_TRUE(w.ok()) << w.message();
  return std::move(w.value());
}

inline Quat about(Vec3 axis, Fixed angle) {
  return from_axis_angle(axis, angle);
}

// A small game: the ground, a sphere, a tilted box and a capsule dropped onto it, a stack of three
// boxes, a sphere resting on a stationary kinematic platform, a kinematic capsule gliding far from
// everything, a static sensor around the stack, and a few material and filter settings. Bodies
// settle and fall asleep within a few hundred frames; contacts carry warm-start impulses.
inline World playground(std::uint64_t seed) {
  WorldDef def;
  def.seed = seed;
  World w = make_world(def);
  add(w, {.type = BodyType::static_body, .shape = Shape::plane()});
  const Fixed damping = 0.3_fx;
  add(w, {.shape = Shape::sphere(0.5_fx),
          .position = {-4_fx, 1_fx, 0_fx},
          .linear_damping = damping,
          .angular_damping = damping});
  add(w, {.shape = Shape::box({0.5_fx, 0.25_fx, 0.4_fx}),
          .position = {-2_fx, 1.5_fx, 0.5_fx},
          .orientation = about({1_fx, 1_fx, 0_fx}, 0.4_fx),
          .friction = 0.8_fx,
          .linear_damping = damping,
          .angular_damping = damping,
          .user_data = 0xDEADBEEFCAFEF00DU});
  add(w, {.shape = Shape::capsule(0.3_fx, 0.4_fx),
          .position = {0_fx, 1_fx, -0.5_fx},
          .orientation = about({0_fx, 0_fx, 1_fx}, 1.5_fx),
          .restitution = 0.4_fx,
          .linear_damping = damping,
          .angular_damping = damping,
          .layer = 2,
          .mask = 3});
  for (int level = 0; level < 3; ++level) {
    add(w, {.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx}),
            .position = {3_fx, Fixed::from_int(level) * 1.05_fx + 0.55_fx, 0_fx},
            .mass = 2_fx,
            .linear_damping = damping,
            .angular_damping = damping,
            .ccd = level == 2});
  }
  add(w, {.type = BodyType::kinematic,
          .shape = Shape::box({1_fx, 0.25_fx, 1_fx}),
          .position = {7_fx, 0.5_fx, 0_fx}});
  add(w, {.shape = Shape::sphere(0.3_fx),
          .position = {7_fx, 1.2_fx, 0_fx},
          .linear_damping = damping,
          .angular_damping = damping});
  add(w, {.type = BodyType::kinematic,
          .shape = Shape::capsule(0.25_fx, 1_fx),
          .position = {-30_fx, 4_fx, 10_fx},
          .linear_velocity = {0.5_fx, 0_fx, 0_fx},
          .angular_velocity = {0_fx, 0.25_fx, 0_fx}});
  add(w, {.type = BodyType::static_body,
          .shape = Shape::box({1_fx, 2_fx, 1_fx}),
          .position = {3_fx, 2_fx, 0_fx},
          .sensor = true});
  return w;
}

// The game's inputs for a frame: a pure function of the frame number and the world's own RNG (so a
// restored world draws the same inputs). Every 45 frames, an impulse in a random direction on a
// random dynamic body (a velocity change of 0.5..3 m/s); a force of 5 m/s^2 times the body's mass
// on a random body every frame until frame 100.
inline void drive(World& w, std::uint64_t frame) {
  const std::vector<BodyId> ids = w.body_ids();
  const auto pick_dynamic = [&]() -> BodyId {
    for (;;) {
      const BodyId id = ids[w.rng().below(ids.size())];
      if (w.body(id)->type == BodyType::dynamic) return id;
    }
  };
  if (frame % 45 == 7) {
    const BodyId id = pick_dynamic();
    const Fixed strength = w.rng().uniform(0.5_fx, 3_fx) * w.body(id)->mass;
    EXPECT_TRUE(w.apply_linear_impulse(id, w.rng().unit_vector() * strength).ok());
  }
  if (frame < 100) {
    const BodyId id = pick_dynamic();
    EXPECT_TRUE(w.apply_force(id, w.rng().unit_vector() * (5_fx * w.body(id)->mass)).ok());
  }
}

inline void run(World& w, std::uint64_t frames) {
  for (std::uint64_t i = 0; i < frames; ++i) {
    drive(w, w.frame());
    w.step();
  }
}

// The playground after `frames` frames of driven play.
inline World played(std::uint64_t seed, std::uint64_t frames) {
  World w = playground(seed);
  run(w, frames);
  return w;
}

// The same, computed once per test program (a copy is returned): stepping is the cost of these
// tests, and most of them only need some realistic state.
inline World played_once(std::uint64_t seed, std::uint64_t frames) {
  static std::map<std::pair<std::uint64_t, std::uint64_t>, World> cache;
  auto it = cache.find({seed, frames});
  if (it == cache.end()) it = cache.emplace(std::pair{seed, frames}, played(seed, frames)).first;
  return it->second;
}

// A settled playground: contacts with warm-start impulses, sleeping bodies, a gliding kinematic.
inline World settled() {
  return played_once(7, 300);
}

// ---- An independent reader of the v1 layout ----
//
// The canonical encoding, version 1, as a compatibility contract (state_io.cpp writes it):
//   "DSIM" u32 version=1 | u64 frame | u32 next_id | WorldDef | 4 x u64 rng |
//   u32 body count, bodies ascending by ID | u32 contact count, contacts ascending by (a, b).
// Integers little-endian, Fixed = raw i64, bool = one byte 0/1, enums one byte, Vec3 = x y z,
// Quat = w x y z. A body: id u32, type u8, shape (type u8, then radius | half extents | radius and
// half height | nothing), position, orientation, linear and angular velocity, mass, inertia,
// friction, restitution, linear and angular damping, layer u32, mask u32, sensor, ccd, user data
// u64, awake, sleep time, force, torque. A contact: a u32, b u32, flags u8 (bit 0 touching, bit 1
// reported by events, no other bit), point count u8, then per point: feature u32, normal impulse,
// two tangent impulses.

struct DecodedContact {
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  bool touching = false;
  bool reported = false;
  std::uint8_t point_count = 0;
  std::size_t at = 0;  // offset of the record
  std::size_t first_impulse_at = 0;
};

struct Decoded {
  bool ok = false;
  std::string error;
  std::uint64_t frame = 0;
  std::uint32_t next_id = 0;
  WorldDef def;
  std::size_t globals_at = 0;  // = 8: frame, next ID, definition
  std::size_t rng_at = 0;
  Rng::State rng{};
  std::size_t body_count_at = 0;
  std::vector<BodyState> bodies;
  std::vector<std::size_t> body_at;
  std::size_t contact_count_at = 0;
  std::vector<DecodedContact> contacts;
  std::size_t end = 0;
};

inline Decoded decode(std::span<const std::uint8_t> bytes) {
  Decoded d;
  ByteReader r(bytes);
  const std::uint32_t magic = r.u32("magic");
  const std::uint32_t version = r.u32("version");
  if (magic != 0x4D495344U || version != 1) {
    d.error = "not a v1 state";
    return d;
  }
  d.globals_at = r.offset();
  d.frame = r.u64("frame");
  d.next_id = r.u32("next id");
  WorldDef& def = d.def;
  def.gravity = r.vec3("gravity");
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
  d.rng_at = r.offset();
  for (std::uint64_t& word : d.rng)
    word = r.u64("rng");
  d.body_count_at = r.offset();
  const std::uint32_t bodies = r.u32("body count");
  for (std::uint32_t i = 0; i < bodies && r.ok(); ++i) {
    d.body_at.push_back(r.offset());
    BodyState b;
    b.id = BodyId{r.u32("id")};
    b.type = static_cast<BodyType>(r.u8("type"));
    b.shape.type = static_cast<ShapeType>(r.u8("shape type"));
    switch (b.shape.type) {
      case ShapeType::sphere:
        b.shape.radius = r.fixed("radius");
        break;
      case ShapeType::box:
        b.shape.half_extents = r.vec3("half extents");
        break;
      case ShapeType::capsule:
        b.shape.radius = r.fixed("radius");
        b.shape.half_height = r.fixed("half height");
        break;
      case ShapeType::plane:
        break;
      default:
        r.fail("shape type", "known");
    }
    b.position = r.vec3("position");
    b.orientation = r.quat("orientation");
    b.linear_velocity = r.vec3("linear velocity");
    b.angular_velocity = r.vec3("angular velocity");
    b.mass = r.fixed("mass");
    b.inertia = r.vec3("inertia");
    b.friction = r.fixed("friction");
    b.restitution = r.fixed("restitution");
    b.linear_damping = r.fixed("linear damping");
    b.angular_damping = r.fixed("angular damping");
    b.layer = r.u32("layer");
    b.mask = r.u32("mask");
    b.sensor = r.boolean("sensor");
    b.ccd = r.boolean("ccd");
    b.user_data = r.u64("user data");
    b.awake = r.boolean("awake");
    b.sleep_time = r.fixed("sleep time");
    b.force = r.vec3("force");
    b.torque = r.vec3("torque");
    d.bodies.push_back(b);
  }
  d.contact_count_at = r.offset();
  const std::uint32_t contacts = r.u32("contact count");
  for (std::uint32_t i = 0; i < contacts && r.ok(); ++i) {
    DecodedContact c;
    c.at = r.offset();
    c.a = r.u32("a");
    c.b = r.u32("b");
    const std::uint8_t flags = r.u8("flags");
    if (flags > 3) r.fail("flags", "bits 0 and 1 only");
    c.touching = (flags & 1U) != 0;
    c.reported = (flags & 2U) != 0;
    c.point_count = r.u8("point count");
    if (c.point_count > 4) r.fail("point count", "<= 4");
    c.first_impulse_at = r.offset() + 4;
    for (std::uint8_t p = 0; p < c.point_count && r.ok(); ++p) {
      (void)r.u32("feature");
      (void)r.fixed("normal impulse");
      (void)r.fixed("tangent impulse 1");
      (void)r.fixed("tangent impulse 2");
    }
    d.contacts.push_back(c);
  }
  d.end = r.offset();
  d.ok = r.ok() && r.at_end();
  if (!r.ok()) d.error = r.error();
  if (r.ok() && !r.at_end()) d.error = "trailing bytes";
  return d;
}

inline std::uint64_t xxh3(std::span<const std::uint8_t> bytes) {
  return XXH3_64bits(bytes.data(), bytes.size());
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

inline bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Field offsets inside a body record, from the layout above (shape payload of a sphere: 8 bytes).
inline constexpr std::size_t kBodyTypeAt = 4;
inline constexpr std::size_t kShapeTypeAt = 5;
inline constexpr std::size_t kSpherePositionAt = 14;
inline constexpr std::size_t kSphereOrientationAt = kSpherePositionAt + 24;

// ---- Rejection checks ----

// Restores `bytes` into `w`, which must refuse them and stay exactly as it was.
// Returns the message ("" when the bytes were wrongly accepted).
inline std::string expect_rejected(World& w, std::span<const std::uint8_t> bytes) {
  const Bytes before = w.save();
  const StateHashes hashes_before = w.hashes();
  const Status st = w.restore(bytes);
  EXPECT_FALSE(st.ok()) << "a corrupt state was accepted";
  if (st.ok()) return {};
  EXPECT_TRUE(contains(st.message(), "byte")) << "no byte offset in: '" << st.message() << "'";
  // Compared as booleans: on failure the message matters, not two dumps of a few kB.
  EXPECT_TRUE(w.save() == before) << "a rejected restore changed the state: " << st.message();
  EXPECT_EQ(w.hashes(), hashes_before);
  return st.message();
}

// The outcome of restoring possibly corrupt bytes into `w`, whose state is `original` (with
// `original_hashes`): either refused with a message and nothing changed, or accepted, in which
// case the world must now save exactly `bytes` (the encoding is canonical); `w` is then put back.
// Returns whether the bytes were accepted; records a failure (and returns false) otherwise.
inline bool restore_outcome_is_sound(World& w, std::span<const std::uint8_t> bytes,
                                     const Bytes& original, const StateHashes& original_hashes,
                                     const std::string& what) {
  const Status st = w.restore(bytes);
  if (st.ok()) {
    const Bytes now = w.save();
    if (!std::equal(now.begin(), now.end(), bytes.begin(), bytes.end())) {
      ADD_FAILURE() << what << ": accepted, but save() does not give the same bytes back";
    }
    const Status back = w.restore(original);
    if (!back.ok()) ADD_FAILURE() << "restoring the original failed: " << back.message();
    return true;
  }
  if (st.message().empty() || !contains(st.message(), "byte"))
    ADD_FAILURE() << what << ": refused without a message naming the byte: '" << st.message()
                  << "'";
  if (w.save() != original || w.hashes() != original_hashes)
    ADD_FAILURE() << what << ": a refused restore changed the state (" << st.message() << ")";
  return false;
}

}  // namespace state_test
}  // namespace detsim

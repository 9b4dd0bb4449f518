// World state: save(), restore(), hashes() and body_hash() (docs/DETERMINISM.md rules 5, 6 and 7).
//
// - A restored world is the saved world: the same bytes, the same hashes, and the same hash on
//   every later frame as a run that never saved.
// - The bytes are canonical: the v1 layout is decoded here by an independent reader and compared
//   field by field with what the public API reports; the hashes are recomputed with xxHash itself.
// - Bad bytes are refused with a message naming the byte, and leave the world exactly as it was
//   (its save() bytes and hashes compared before and after every rejected restore).
//
// Worlds are built through the public API only.
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
namespace {
std::atomic<std::size_t> g_largest_allocation{0};
}  // namespace

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

namespace {

using namespace detsim::literals;
using Bytes = std::vector<std::uint8_t>;

// ---- Scenes, built through the public API ----

BodyId add(World& w, const BodyDef& def) {
  const Expected<BodyId> id = w.create_body(def);
  EXPECT_TRUE(id.ok()) << id.message();
  return id.ok() ? id.value() : BodyId{};
}

World make_world(const WorldDef& def) {
  Expected<World> w = World::create(def);
  EXPECT_TRUE(w.ok()) << w.message();
  return std::move(w.value());
}

Quat about(Vec3 axis, Fixed angle) {
  return from_axis_angle(axis, angle);
}

// A small game: the ground, a sphere, a tilted box and a capsule dropped onto it, a stack of three
// boxes, a sphere resting on a stationary kinematic platform, a kinematic capsule gliding far from
// everything, a static sensor around the stack, and a few material and filter settings. Bodies
// settle and fall asleep within a few hundred frames; contacts carry warm-start impulses.
World playground(std::uint64_t seed) {
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
void drive(World& w, std::uint64_t frame) {
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

void run(World& w, std::uint64_t frames) {
  for (std::uint64_t i = 0; i < frames; ++i) {
    drive(w, w.frame());
    w.step();
  }
}

// The playground after `frames` frames of driven play.
World played(std::uint64_t seed, std::uint64_t frames) {
  World w = playground(seed);
  run(w, frames);
  return w;
}

// The same, computed once per test program (a copy is returned): stepping is the cost of these
// tests, and most of them only need some realistic state.
World played_once(std::uint64_t seed, std::uint64_t frames) {
  static std::map<std::pair<std::uint64_t, std::uint64_t>, World> cache;
  auto it = cache.find({seed, frames});
  if (it == cache.end()) it = cache.emplace(std::pair{seed, frames}, played(seed, frames)).first;
  return it->second;
}

// A settled playground: contacts with warm-start impulses, sleeping bodies, a gliding kinematic.
World settled() {
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

Decoded decode(std::span<const std::uint8_t> bytes) {
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

std::uint64_t xxh3(std::span<const std::uint8_t> bytes) {
  return XXH3_64bits(bytes.data(), bytes.size());
}

void put_u32(Bytes& bytes, std::size_t at, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i)
    bytes[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

void put_i64(Bytes& bytes, std::size_t at, std::int64_t value) {
  const auto v = static_cast<std::uint64_t>(value);
  for (std::size_t i = 0; i < 8; ++i)
    bytes[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Field offsets inside a body record, from the layout above (shape payload of a sphere: 8 bytes).
constexpr std::size_t kBodyTypeAt = 4;
constexpr std::size_t kShapeTypeAt = 5;
constexpr std::size_t kSpherePositionAt = 14;
constexpr std::size_t kSphereOrientationAt = kSpherePositionAt + 24;

// ---- Rejection checks ----

// Restores `bytes` into `w`, which must refuse them and stay exactly as it was.
// Returns the message ("" when the bytes were wrongly accepted).
std::string expect_rejected(World& w, std::span<const std::uint8_t> bytes) {
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
bool restore_outcome_is_sound(World& w, std::span<const std::uint8_t> bytes, const Bytes& original,
                              const StateHashes& original_hashes, const std::string& what) {
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

// ======================================================================================
// The format
// ======================================================================================

TEST(StateFormat, DefaultWorldStartsWithMagicAndVersion) {
  const World w;
  const Bytes bytes = w.save();
  ASSERT_GE(bytes.size(), 8U);
  EXPECT_EQ(bytes[0], 'D');
  EXPECT_EQ(bytes[1], 'S');
  EXPECT_EQ(bytes[2], 'I');
  EXPECT_EQ(bytes[3], 'M');
  EXPECT_EQ((Bytes(bytes.begin() + 4, bytes.begin() + 8)), (Bytes{1, 0, 0, 0}));
  // Then frame 0 (u64) and the next body ID, 1 (u32).
  EXPECT_EQ((Bytes(bytes.begin() + 8, bytes.begin() + 20)),
            (Bytes{0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0}));
  // magic 4 + version 4 + frame 8 + next ID 4 + definition 137 + RNG 32 + two empty counts 8.
  EXPECT_EQ(bytes.size(), 197U);
  EXPECT_EQ((Bytes(bytes.end() - 8, bytes.end())), (Bytes{0, 0, 0, 0, 0, 0, 0, 0}));

  const Decoded d = decode(bytes);
  ASSERT_TRUE(d.ok) << d.error;
  EXPECT_EQ(d.def, WorldDef{});
  EXPECT_EQ(d.rng, Rng(0).state());
}

TEST(StateFormat, DecodesToExactlyWhatTheWorldReports) {
  const World w = settled();
  const Bytes bytes = w.save();
  const Decoded d = decode(bytes);
  ASSERT_TRUE(d.ok) << d.error;
  EXPECT_EQ(d.frame, 300U);
  EXPECT_EQ(d.frame, w.frame());
  EXPECT_EQ(d.def, w.def());
  EXPECT_EQ(d.rng, w.rng().state());
  EXPECT_EQ(d.next_id, w.body_ids().back().value + 1);

  const std::vector<BodyId> ids = w.body_ids();
  ASSERT_EQ(d.bodies.size(), ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const Expected<BodyState> b = w.body(ids[i]);
    ASSERT_TRUE(b.ok());
    EXPECT_TRUE(d.bodies[i] == b.value()) << "body " << ids[i].value << " decodes differently";
    if (i > 0) {
      EXPECT_LT(d.bodies[i - 1].id, d.bodies[i].id);
    }
  }
  // The scene must exercise what the state carries: contacts (touching, with points), sleeping
  // bodies, and a kinematic body in motion.
  ASSERT_FALSE(d.contacts.empty());
  std::size_t touching = 0;
  std::size_t reported = 0;
  for (std::size_t i = 0; i < d.contacts.size(); ++i) {
    const DecodedContact& c = d.contacts[i];
    EXPECT_LT(c.a, c.b);
    EXPECT_TRUE(w.contains(BodyId{c.a}) && w.contains(BodyId{c.b}));
    if (i > 0) {
      const DecodedContact& p = d.contacts[i - 1];
      EXPECT_TRUE(p.a < c.a || (p.a == c.a && p.b < c.b)) << "contacts not in ascending order";
    }
    touching += c.touching ? 1 : 0;
    reported += c.reported ? 1 : 0;
    EXPECT_EQ(c.touching, c.point_count > 0);
    EXPECT_TRUE(c.touching || !c.reported);
  }
  EXPECT_GE(touching, 5U);
  EXPECT_GE(reported, 5U);
  const auto asleep = std::count_if(d.bodies.begin(), d.bodies.end(), [](const BodyState& b) {
    return b.type == BodyType::dynamic && !b.awake;
  });
  EXPECT_GE(asleep, 3) << "the scene should have sleeping bodies by frame 300";
}

TEST(StateFormat, HashesAreXxh3OfTheCanonicalSections) {
  World w = settled();
  // Unconsumed inputs are state too: leave some force on a body.
  ASSERT_TRUE(w.apply_force(BodyId{2}, {1_fx, 2_fx, 3_fx}).ok());
  const Bytes bytes = w.save();
  const Decoded d = decode(bytes);
  ASSERT_TRUE(d.ok) << d.error;
  const std::span<const std::uint8_t> all(bytes);
  const StateHashes h = w.hashes();
  EXPECT_EQ(h.total, xxh3(all));
  EXPECT_EQ(h.globals, xxh3(all.subspan(d.globals_at, d.rng_at - d.globals_at)));
  EXPECT_EQ(h.rng, xxh3(all.subspan(d.rng_at, d.body_count_at - d.rng_at)));
  EXPECT_EQ(h.bodies, xxh3(all.subspan(d.body_count_at, d.contact_count_at - d.body_count_at)));
  EXPECT_EQ(h.contacts, xxh3(all.subspan(d.contact_count_at)));
  for (std::size_t i = 0; i < d.bodies.size(); ++i) {
    const std::size_t end = i + 1 < d.bodies.size() ? d.body_at[i + 1] : d.contact_count_at;
    const Expected<std::uint64_t> bh = w.body_hash(d.bodies[i].id);
    ASSERT_TRUE(bh.ok());
    EXPECT_EQ(bh.value(), xxh3(all.subspan(d.body_at[i], end - d.body_at[i])))
        << "body " << d.bodies[i].id.value;
  }
}

// ======================================================================================
// Save and restore
// ======================================================================================

void expect_same_world(const World& a, const World& b) {
  EXPECT_EQ(a.save(), b.save());
  EXPECT_EQ(a.hashes(), b.hashes());
  EXPECT_EQ(a.def(), b.def());
  EXPECT_EQ(a.frame(), b.frame());
  EXPECT_EQ(a.rng(), b.rng());
  ASSERT_EQ(a.body_ids(), b.body_ids());
  for (const BodyId id : a.body_ids()) {
    EXPECT_TRUE(a.body(id).value() == b.body(id).value()) << "body " << id.value;
    EXPECT_EQ(a.body_hash(id).value(), b.body_hash(id).value()) << "body " << id.value;
  }
}

TEST(SaveRestore, RoundTripIsExact) {
  std::vector<World> worlds;
  worlds.emplace_back();                 // default, empty
  worlds.push_back(playground(1));       // fresh, never stepped
  worlds.push_back(played_once(2, 60));  // in flight, forces pending
  worlds.push_back(settled());           // settled: contacts and sleep
  World destroyed = settled();           // with a gap in the IDs
  ASSERT_TRUE(destroyed.destroy_body(BodyId{6}).ok());
  worlds.push_back(destroyed);
  for (std::size_t i = 0; i < worlds.size(); ++i) {
    SCOPED_TRACE(testing::Message() << "world " << i);
    const Bytes bytes = worlds[i].save();
    World fresh;
    const Status st = fresh.restore(bytes);
    ASSERT_TRUE(st.ok()) << st.message();
    expect_same_world(fresh, worlds[i]);
    // Restoring over a world that already has a (different) state replaces all of it.
    World busy = played_once(22, 120);
    ASSERT_TRUE(busy.restore(bytes).ok());
    expect_same_world(busy, worlds[i]);
  }
}

// Steps `w` (driven) to frame `to`, recording hashes() after every step.
std::vector<StateHashes> hashes_until(World& w, std::uint64_t to) {
  std::vector<StateHashes> out;
  while (w.frame() < to) {
    drive(w, w.frame());
    w.step();
    out.push_back(w.hashes());
  }
  return out;
}

TEST(SaveRestore, RestoredWorldStepsLikeOneThatNeverSaved) {
  // One uninterrupted, driven run to frame n, saving at several frames k on the way: before any
  // contact, while the bodies first land, while forces are pending, and while the stack sleeps
  // just before an impulse wakes it (in this scene the stack is asleep at frames 130-145 and
  // 345-365; the drive's impulses come at frames 142, ..., 367). A world restored from each save
  // must then reproduce every later frame's hashes.
  constexpr std::uint64_t n = 400;
  const std::vector<std::uint64_t> save_at{0, 25, 97, 135, 231, 355};
  World original = playground(5);
  std::vector<Bytes> saved;
  std::vector<StateHashes> reference;  // reference[f - 1]: the hashes after frame f
  while (original.frame() < n) {
    if (std::find(save_at.begin(), save_at.end(), original.frame()) != save_at.end())
      saved.push_back(original.save());
    drive(original, original.frame());
    original.step();
    reference.push_back(original.hashes());
  }
  ASSERT_EQ(saved.size(), save_at.size());
  const Bytes at_n = original.save();

  for (std::size_t i = 0; i < save_at.size(); ++i) {
    const std::uint64_t k = save_at[i];
    SCOPED_TRACE(testing::Message() << "saved at frame " << k);
    World restored;
    ASSERT_TRUE(restored.restore(saved[i]).ok());
    ASSERT_EQ(restored.frame(), k);
    const std::vector<StateHashes> replay = hashes_until(restored, n);
    ASSERT_EQ(replay.size(), n - k);
    for (std::size_t f = 0; f < replay.size(); ++f)
      ASSERT_EQ(replay[f], reference[k + f]) << "first divergence at frame " << k + f + 1;
    EXPECT_EQ(restored.save(), at_n);
  }

  // Rewind the original itself (save at k, step to n, restore, step to n again).
  const std::uint64_t k = save_at[3];
  ASSERT_TRUE(original.restore(saved[3]).ok());
  ASSERT_EQ(original.frame(), k);
  const std::vector<StateHashes> again = hashes_until(original, n);
  for (std::size_t f = 0; f < again.size(); ++f)
    ASSERT_EQ(again[f], reference[k + f]) << "rewound: first divergence at frame " << k + f + 1;
  EXPECT_EQ(original.save(), at_n);
}

TEST(SaveRestore, CopiesAndMovesCarryTheWholeState) {
  const World source = settled();
  World copy = source;
  World assigned;
  assigned = source;
  World moved_from = source;
  const World moved = std::move(moved_from);
  expect_same_world(copy, source);
  expect_same_world(assigned, source);
  expect_same_world(moved, source);
  // And they step alike.
  World a = source;
  run(a, 50);
  run(copy, 50);
  EXPECT_EQ(a.hashes(), copy.hashes());
}

// ======================================================================================
// Corrupt input changes nothing
// ======================================================================================

class RejectedRestore : public testing::Test {
 protected:
  void SetUp() override {
    source_ = settled();
    state_ = source_.save();
    decoded_ = decode(state_);
    ASSERT_TRUE(decoded_.ok) << decoded_.error;
    ASSERT_GE(decoded_.contacts.size(), 3U);
    // The target holds a different state, so that "unchanged" means something.
    target_ = played_once(22, 120);
    target_state_ = target_.save();
    target_hashes_ = target_.hashes();
  }

  World source_;
  Bytes state_;
  Decoded decoded_;
  World target_;
  Bytes target_state_;
  StateHashes target_hashes_;
};

TEST_F(RejectedRestore, EveryTruncation) {
  for (std::size_t n = 0; n < state_.size(); ++n) {
    const Status st = target_.restore(std::span<const std::uint8_t>(state_.data(), n));
    ASSERT_FALSE(st.ok()) << "a " << n << "-byte prefix of a " << state_.size()
                          << "-byte state was accepted";
    ASSERT_TRUE(contains(st.message(), "byte")) << n << ": " << st.message();
    // Checking every prefix's effect by bytes is the cost driver; the hashes are compared on a
    // sample (they are a function of the same state).
    ASSERT_TRUE(target_.save() == target_state_) << "prefix " << n << " changed the state";
    if (n % 97 == 0) {
      ASSERT_EQ(target_.hashes(), target_hashes_) << "prefix " << n;
    }
  }
  // The untruncated state is fine.
  ASSERT_TRUE(target_.restore(state_).ok());
  EXPECT_EQ(target_.save(), state_);
}

TEST_F(RejectedRestore, EveryBitFlipInTheHeader) {
  // The header: magic, version, globals, RNG and the body count.
  const std::size_t header = decoded_.body_count_at + 4;
  std::size_t accepted = 0;
  Bytes flipped = state_;
  for (std::size_t at = 0; at < header; ++at) {
    for (int bit = 0; bit < 8; ++bit) {
      flipped[at] = static_cast<std::uint8_t>(state_[at] ^ (1U << bit));
      const std::string what = "byte " + std::to_string(at) + " bit " + std::to_string(bit);
      if (restore_outcome_is_sound(target_, flipped, target_state_, target_hashes_, what))
        ++accepted;
      flipped[at] = state_[at];
    }
  }
  // Magic, version and the body count can never flip to a valid state; the frame number, the
  // seed and most of the RNG state always do.
  EXPECT_GT(accepted, 64U * 3);
  EXPECT_LT(accepted, header * 8 - (4 + 4 + 4) * 8);
}

TEST_F(RejectedRestore, BitFlipsAcrossBodiesAndContacts) {
  // Every bit of every contact byte and of the first three body records (a plane, a sphere and a
  // box), and every bit of every third byte of the other bodies (record sizes are not multiples of
  // 3, so the sampled phase shifts from body to body).
  std::vector<std::size_t> positions;
  const std::size_t dense_until = decoded_.body_at[3];
  for (std::size_t at = decoded_.body_count_at + 4; at < decoded_.contact_count_at; ++at) {
    if (at < dense_until || at % 3 == 0) positions.push_back(at);
  }
  for (std::size_t at = decoded_.contact_count_at; at < state_.size(); ++at)
    positions.push_back(at);
  std::size_t accepted = 0;
  std::size_t refused = 0;
  Bytes flipped = state_;
  for (const std::size_t at : positions) {
    for (int bit = 0; bit < 8; ++bit) {
      flipped[at] = static_cast<std::uint8_t>(state_[at] ^ (1U << bit));
      const std::string what = "byte " + std::to_string(at) + " bit " + std::to_string(bit);
      if (restore_outcome_is_sound(target_, flipped, target_state_, target_hashes_, what)) {
        ++accepted;
      } else {
        ++refused;
      }
      flipped[at] = state_[at];
    }
  }
  EXPECT_GT(accepted, 0U);
  EXPECT_GT(refused, 0U);
}

TEST_F(RejectedRestore, RandomByteStrings) {
  Rng rng(0xBAD5EED);
  const Bytes prefix(state_.begin(), state_.begin() + 8);  // a valid magic and version
  for (int i = 0; i < 10000; ++i) {
    Bytes junk(rng.below(600));
    for (std::uint8_t& b : junk)
      b = static_cast<std::uint8_t>(rng.next_u64());
    // A third plain junk, a third behind a valid magic and version, a third behind a real header
    // (so that the body and contact readers see garbage too).
    if (i % 3 == 1) junk.insert(junk.begin(), prefix.begin(), prefix.end());
    if (i % 3 == 2) {
      junk.insert(junk.begin(), state_.begin(),
                  state_.begin() + static_cast<std::ptrdiff_t>(decoded_.body_count_at));
    }
    restore_outcome_is_sound(target_, junk, target_state_, target_hashes_,
                             "random string " + std::to_string(i));
    if (testing::Test::HasFailure()) break;
  }
}

TEST_F(RejectedRestore, GarbageAfterAValidState) {
  Rng rng(4);
  for (std::size_t extra = 1; extra <= 64; ++extra) {
    Bytes longer = state_;
    for (std::size_t i = 0; i < extra; ++i)
      longer.push_back(static_cast<std::uint8_t>(rng.next_u64()));
    const std::string message = expect_rejected(target_, longer);
    EXPECT_TRUE(contains(message, "byte " + std::to_string(state_.size()))) << message;
  }
  Bytes twice = state_;
  twice.insert(twice.end(), state_.begin(), state_.end());
  expect_rejected(target_, twice);
  Bytes zero_tail = state_;
  zero_tail.push_back(0);
  expect_rejected(target_, zero_tail);
}

TEST_F(RejectedRestore, HugeCountsInFewBytesFailWithoutAllocating) {
  // The header of a real state, then a body count of 2^32 - 1 and a handful of bytes.
  for (const std::uint32_t count : {0xFFFFFFFFU, 0x10000000U, 100000U, 5U}) {
    Bytes hostile(state_.begin(),
                  state_.begin() + static_cast<std::ptrdiff_t>(decoded_.body_count_at));
    hostile.resize(hostile.size() + 4 + 64, 0x01);
    put_u32(hostile, decoded_.body_count_at, count);
    g_largest_allocation = 0;
    const std::string message = expect_rejected(target_, hostile);
    EXPECT_LT(g_largest_allocation.load(), std::size_t{64} * 1024)
        << "body count " << count << ": largest allocation " << g_largest_allocation.load();
    EXPECT_TRUE(contains(message, "byte")) << message;
  }
  // The same for the contact count, after the real bodies.
  for (const std::uint32_t count : {0xFFFFFFFFU, 0x01000000U}) {
    Bytes hostile(state_.begin(),
                  state_.begin() + static_cast<std::ptrdiff_t>(decoded_.contact_count_at));
    hostile.resize(hostile.size() + 4 + 32, 0x02);
    put_u32(hostile, decoded_.contact_count_at, count);
    g_largest_allocation = 0;
    expect_rejected(target_, hostile);
    EXPECT_LT(g_largest_allocation.load(), std::size_t{64} * 1024 + state_.size() * 4)
        << "contact count " << count << ": largest allocation " << g_largest_allocation.load();
  }
  // A count just within what the bytes could hold if bodies were tiny: the allocation stays
  // proportional to the input.
  Bytes padded(state_.begin(),
               state_.begin() + static_cast<std::ptrdiff_t>(decoded_.body_count_at));
  padded.resize(padded.size() + 4 + 100000, 0x00);
  put_u32(padded, decoded_.body_count_at, 100000U / 46);
  g_largest_allocation = 0;
  expect_rejected(target_, padded);
  EXPECT_LT(g_largest_allocation.load(), padded.size() * 16);
}

TEST_F(RejectedRestore, WrongMagicOrVersion) {
  Bytes bad = state_;
  bad[0] = 'X';
  std::string message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "magic")) << message;

  for (const std::uint32_t version : {0U, 2U, 0xFFFFFFFFU, 0x01000000U}) {
    bad = state_;
    put_u32(bad, 4, version);
    message = expect_rejected(target_, bad);
    EXPECT_TRUE(contains(message, "version " + std::to_string(version))) << message;
  }
  expect_rejected(target_, Bytes{'D', 'S', 'I', 'M'});
  expect_rejected(target_, Bytes{});
}

TEST_F(RejectedRestore, BodyIdsMustBeAscendingUniqueAndKnown) {
  const std::vector<std::size_t>& at = decoded_.body_at;
  ASSERT_GE(at.size(), 3U);
  const std::uint32_t first = decoded_.bodies[0].id.value;
  const std::uint32_t second = decoded_.bodies[1].id.value;

  Bytes bad = state_;
  put_u32(bad, at[1], first);  // a duplicate
  std::string message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "ascending")) << message;
  EXPECT_TRUE(contains(message, "byte " + std::to_string(at[1]))) << message;

  bad = state_;
  put_u32(bad, at[0], second);  // 2, 2, ...
  put_u32(bad, at[1], first);   // then 1: descending
  expect_rejected(target_, bad);

  bad = state_;
  put_u32(bad, at[2], 0);  // the null ID
  expect_rejected(target_, bad);

  bad = state_;
  put_u32(bad, at.back(), decoded_.next_id);  // not yet issued
  message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "byte")) << message;
}

TEST_F(RejectedRestore, UnknownShapeOrBodyType) {
  const std::size_t body = decoded_.body_at[1];
  for (const std::uint8_t type :
       {std::uint8_t{0}, std::uint8_t{5}, std::uint8_t{0x80}, std::uint8_t{0xFF}}) {
    Bytes bad = state_;
    bad[body + kShapeTypeAt] = type;
    const std::string message = expect_rejected(target_, bad);
    EXPECT_TRUE(contains(message, "shape type")) << message;
  }
  for (const std::uint8_t type : {std::uint8_t{3}, std::uint8_t{0xFF}}) {
    Bytes bad = state_;
    bad[body + kBodyTypeAt] = type;
    const std::string message = expect_rejected(target_, bad);
    EXPECT_TRUE(contains(message, "body type")) << message;
  }
  // A dynamic plane.
  Bytes bad = state_;
  ASSERT_EQ(decoded_.bodies[0].shape.type, ShapeType::plane);
  bad[decoded_.body_at[0] + kBodyTypeAt] = 2;
  expect_rejected(target_, bad);
}

TEST_F(RejectedRestore, NonUnitQuaternion) {
  // Body 2 is a sphere: its orientation follows its 8-byte radius.
  ASSERT_EQ(decoded_.bodies[1].shape.type, ShapeType::sphere);
  const std::size_t q = decoded_.body_at[1] + kSphereOrientationAt;
  for (const std::int64_t w : {std::int64_t{0}, 2 * Fixed::one_raw, -(std::int64_t{1} << 62)}) {
    Bytes bad = state_;
    put_i64(bad, q, w);
    put_i64(bad, q + 8, 0);
    put_i64(bad, q + 16, 0);
    put_i64(bad, q + 24, 0);
    const std::string message = expect_rejected(target_, bad);
    EXPECT_TRUE(contains(message, "unit quaternion")) << message;
    EXPECT_TRUE(contains(message, "byte " + std::to_string(decoded_.body_at[1]))) << message;
  }
  // Just outside the tolerance (|q|^2 - 1 > 2^-20) is refused; the identity is fine.
  Bytes bad = state_;
  put_i64(bad, q, Fixed::one_raw + (Fixed::one_raw >> 19));
  put_i64(bad, q + 8, 0);
  put_i64(bad, q + 16, 0);
  put_i64(bad, q + 24, 0);
  expect_rejected(target_, bad);
  Bytes good = bad;
  put_i64(good, q, Fixed::one_raw);
  ASSERT_TRUE(target_.restore(good).ok());
  EXPECT_EQ(target_.save(), good);
}

TEST_F(RejectedRestore, ContactsMustNameExistingBodiesInOrder) {
  const DecodedContact& last = decoded_.contacts.back();
  Bytes bad = state_;
  put_u32(bad, last.at + 4, 0xFFFFFFF0U);  // b: no such body (and still ascending)
  std::string message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "does not exist")) << message;

  // A body ID that was once issued, but not to a body in this state.
  World gap = source_;
  const BodyId removed = gap.body_ids()[4];
  const Bytes with_gap_bytes = [&] {
    EXPECT_TRUE(gap.destroy_body(removed).ok());
    return gap.save();
  }();
  const Decoded with_gap = decode(with_gap_bytes);
  ASSERT_TRUE(with_gap.ok);
  ASSERT_FALSE(with_gap.contacts.empty());
  bad = with_gap_bytes;
  const DecodedContact& c = with_gap.contacts.front();
  ASSERT_LT(c.a, removed.value);
  put_u32(bad, c.at + 4, removed.value);
  expect_rejected(target_, bad);

  bad = state_;  // a == b
  put_u32(bad, last.at + 4, last.a);
  expect_rejected(target_, bad);

  bad = state_;  // the pair reversed
  put_u32(bad, last.at, last.b);
  put_u32(bad, last.at + 4, last.a);
  expect_rejected(target_, bad);

  // A duplicate pair: the first contact written twice.
  const DecodedContact& c0 = decoded_.contacts[0];
  const std::size_t c0_end = decoded_.contacts[1].at;
  bad.assign(state_.begin(), state_.end());
  bad.insert(bad.begin() + static_cast<std::ptrdiff_t>(c0_end),
             state_.begin() + static_cast<std::ptrdiff_t>(c0.at),
             state_.begin() + static_cast<std::ptrdiff_t>(c0_end));
  put_u32(bad, decoded_.contact_count_at, static_cast<std::uint32_t>(decoded_.contacts.size() + 1));
  message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "ascending")) << message;

  // More than four points.
  bad = state_;
  bad[last.at + 9] = 5;
  expect_rejected(target_, bad);
}

TEST_F(RejectedRestore, ContactFlagsMustBeConsistent) {
  const auto with_points = std::find_if(decoded_.contacts.begin(), decoded_.contacts.end(),
                                        [](const DecodedContact& c) { return c.point_count > 0; });
  ASSERT_NE(with_points, decoded_.contacts.end());
  for (const int flags : {4, 0x81, 0xFF}) {  // bits that mean nothing
    Bytes bad = state_;
    bad[with_points->at + 8] = static_cast<std::uint8_t>(flags);
    const std::string message = expect_rejected(target_, bad);
    EXPECT_TRUE(contains(message, "contact flags")) << message;
  }
  // The same contact without its points (the record is then consistent with flags 0): reported
  // as touching (bit 1) without points, and touching (bit 0) without points, are refused.
  Bytes no_points = state_;
  const auto points_at = static_cast<std::ptrdiff_t>(with_points->at + 10);
  no_points.erase(no_points.begin() + points_at,
                  no_points.begin() + points_at + 28 * with_points->point_count);
  no_points[with_points->at + 9] = 0;
  no_points[with_points->at + 8] = 0;
  {
    World w;
    EXPECT_TRUE(w.restore(no_points).ok()) << "the edited record itself should be valid";
  }
  for (const int flags : {2, 3}) {
    Bytes bad = no_points;
    bad[with_points->at + 8] = static_cast<std::uint8_t>(flags);
    const std::string message = expect_rejected(target_, bad);
    EXPECT_TRUE(contains(message, "without contact points") || contains(message, "point count"))
        << message;
  }
  // Points but not touching.
  Bytes bad = state_;
  bad[with_points->at + 8] = 0;
  expect_rejected(target_, bad);
}

TEST_F(RejectedRestore, NextIdZeroIsRefused) {
  // The ID counter of a real world starts at 1 and stops at 2^32 - 1 (create_body refuses there),
  // so 0 never occurs. With bodies present, restore refuses it (every ID must be below it); with
  // none, it must be refused too, or the next create_body hands out the null ID 0 ("Zero is the
  // null ID", body.hpp).
  Bytes bad = World().save();
  put_u32(bad, 8 + 8, 0);  // after magic, version and the frame
  World w;
  if (w.restore(bad).ok()) {
    const Expected<BodyId> id = w.create_body(BodyDef{});
    ASSERT_TRUE(id.ok()) << id.message();
    ADD_FAILURE() << "a state with next body ID 0 (and no bodies) was accepted; create_body then "
                     "returned ID "
                  << id.value().value << (id.value().is_null() ? " (the null ID)" : "");
    return;
  }
  expect_rejected(target_, bad);
}

TEST_F(RejectedRestore, OtherInvalidValues) {
  Bytes bad = state_;
  for (std::size_t i = 0; i < 32; ++i)
    bad[decoded_.rng_at + i] = 0;  // the one state xoshiro cannot leave
  std::string message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "rng")) << message;

  bad = state_;
  put_i64(bad, decoded_.globals_at + 12 + 24, 0);  // dt = 0
  message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "dt")) << message;

  bad = state_;
  put_u32(bad, decoded_.globals_at + 12 + 24 + 8, 0);  // substeps = 0
  expect_rejected(target_, bad);

  // A static body (the ground) marked awake.
  ASSERT_EQ(decoded_.bodies[0].type, BodyType::static_body);
  bad = state_;
  const std::size_t plane_awake_at =
      decoded_.body_at[0] + 6 + 24 + 32 + 24 + 24 + 8 + 24 + 32 + 4 + 4 + 1 + 1 + 8;
  ASSERT_EQ(bad[plane_awake_at], 0);
  bad[plane_awake_at] = 1;
  expect_rejected(target_, bad);
  bad[plane_awake_at] = 2;  // not a bool
  message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "awake")) << message;

  // A dynamic sphere with negative mass.
  bad = state_;
  const std::size_t mass_at = decoded_.body_at[1] + kSpherePositionAt + 24 + 32 + 24 + 24;
  put_i64(bad, mass_at, -Fixed::one_raw);
  expect_rejected(target_, bad);
}

// ======================================================================================
// Hashes
// ======================================================================================

struct HashSnapshot {
  StateHashes world;
  std::vector<std::uint64_t> bodies;
};

HashSnapshot snapshot(const World& w) {
  HashSnapshot s{w.hashes(), {}};
  for (const BodyId id : w.body_ids())
    s.bodies.push_back(w.body_hash(id).value());
  return s;
}

// After a change to body `touched` only: the total and body hashes changed, and only its body_hash.
void expect_only_body_changed(const World& w, const HashSnapshot& before, BodyId touched) {
  const HashSnapshot after = snapshot(w);
  EXPECT_NE(after.world.total, before.world.total);
  EXPECT_NE(after.world.bodies, before.world.bodies);
  EXPECT_EQ(after.world.globals, before.world.globals);
  EXPECT_EQ(after.world.rng, before.world.rng);
  EXPECT_EQ(after.world.contacts, before.world.contacts);
  const std::vector<BodyId> ids = w.body_ids();
  ASSERT_EQ(after.bodies.size(), before.bodies.size());
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] == touched) {
      EXPECT_NE(after.bodies[i], before.bodies[i]) << "body " << ids[i].value;
    } else {
      EXPECT_EQ(after.bodies[i], before.bodies[i]) << "body " << ids[i].value;
    }
  }
}

TEST(StateHashes, OneBodyFieldChangesItsHashesOnly) {
  const World base = settled();
  const std::vector<BodyId> ids = base.body_ids();
  // For each dynamic or kinematic body (asleep or awake), several single-field changes.
  for (const BodyId id : ids) {
    const BodyState b = base.body(id).value();
    if (b.type == BodyType::static_body) continue;
    SCOPED_TRACE(testing::Message() << "body " << id.value);
    const HashSnapshot before = snapshot(base);
    {
      World w = base;
      Vec3 v = b.linear_velocity;
      v.y += Fixed::epsilon();  // one ulp
      ASSERT_TRUE(w.set_linear_velocity(id, v).ok());
      expect_only_body_changed(w, before, id);
    }
    {
      World w = base;
      ASSERT_TRUE(w.set_angular_velocity(id, b.angular_velocity + Vec3{0_fx, 0_fx, 1_fx}).ok());
      expect_only_body_changed(w, before, id);
    }
    {
      World w = base;
      ASSERT_TRUE(
          w.set_transform(id, b.position + Vec3{Fixed::epsilon(), 0_fx, 0_fx}, b.orientation).ok());
      expect_only_body_changed(w, before, id);
    }
    {
      World w = base;
      ASSERT_TRUE(w.apply_torque(id, {0_fx, 0_fx, 1_fx}).ok());
      expect_only_body_changed(w, before, id);
    }
  }
}

TEST(StateHashes, EachPartHasItsOwnHash) {
  const World base = settled();
  const HashSnapshot before = snapshot(base);
  {
    // The RNG: one draw changes the rng hash and the total only.
    World w = base;
    (void)w.rng().next_u64();
    const StateHashes h = w.hashes();
    EXPECT_NE(h.total, before.world.total);
    EXPECT_NE(h.rng, before.world.rng);
    EXPECT_EQ(h.globals, before.world.globals);
    EXPECT_EQ(h.bodies, before.world.bodies);
    EXPECT_EQ(h.contacts, before.world.contacts);
  }
  {
    // The globals: creating and destroying a body leaves every body and contact as it was but
    // advances the ID counter.
    World w = base;
    const BodyId extra = add(w, {.position = {100_fx, 100_fx, 100_fx}});
    ASSERT_TRUE(w.destroy_body(extra).ok());
    const HashSnapshot after = snapshot(w);
    EXPECT_NE(after.world.total, before.world.total);
    EXPECT_NE(after.world.globals, before.world.globals);
    EXPECT_EQ(after.world.rng, before.world.rng);
    EXPECT_EQ(after.world.bodies, before.world.bodies);
    EXPECT_EQ(after.world.contacts, before.world.contacts);
    EXPECT_EQ(after.bodies, before.bodies);
  }
  {
    // The contacts: one warm-start impulse changed (through the bytes; no API edits contacts).
    Bytes bytes = base.save();
    const Decoded d = decode(bytes);
    ASSERT_TRUE(d.ok);
    const auto touching = std::find_if(d.contacts.begin(), d.contacts.end(),
                                       [](const DecodedContact& c) { return c.point_count > 0; });
    ASSERT_NE(touching, d.contacts.end());
    bytes[touching->first_impulse_at] ^= 1;
    World w;
    ASSERT_TRUE(w.restore(bytes).ok());
    const HashSnapshot after = snapshot(w);
    EXPECT_NE(after.world.total, before.world.total);
    EXPECT_NE(after.world.contacts, before.world.contacts);
    EXPECT_EQ(after.world.globals, before.world.globals);
    EXPECT_EQ(after.world.rng, before.world.rng);
    EXPECT_EQ(after.world.bodies, before.world.bodies);
    EXPECT_EQ(after.bodies, before.bodies);
  }
  {
    // A step changes the frame number at least.
    World w = base;
    w.step();
    EXPECT_NE(w.hashes().globals, before.world.globals);
    EXPECT_NE(w.hashes().total, before.world.total);
  }
}

TEST(StateHashes, BodyHashOfAnUnknownIdIsAnError) {
  World w = playground(3);
  EXPECT_FALSE(w.body_hash(BodyId{}).ok());
  EXPECT_FALSE(w.body_hash(BodyId{999}).ok());
  EXPECT_FALSE(w.body_hash(BodyId{0xFFFFFFFFU}).ok());
  EXPECT_FALSE(w.body_hash(BodyId{999}).message().empty());
  const BodyId gone = w.body_ids()[2];
  ASSERT_TRUE(w.body_hash(gone).ok());
  ASSERT_TRUE(w.destroy_body(gone).ok());
  EXPECT_FALSE(w.body_hash(gone).ok());
  EXPECT_FALSE(World().body_hash(BodyId{1}).ok());
}

TEST(StateHashes, IdenticalWorldsHashIdenticallyAndDifferentSeedsDiffer) {
  // Two independent runs (not the cache).
  const World a = played(40, 90);
  const World b = played(40, 90);
  EXPECT_EQ(a.hashes(), b.hashes());
  const World c = played(41, 90);
  EXPECT_NE(a.hashes().total, c.hashes().total);
  EXPECT_NE(a.hashes().rng, c.hashes().rng);
}

// ======================================================================================
// Canonical bytes
// ======================================================================================

TEST(CanonicalBytes, TheSameStateBuiltTwoWaysSavesTheSameBytes) {
  const Vec3 position{1.25_fx, 3_fx, -2_fx};
  const Quat orientation = about({0_fx, 1_fx, 1_fx}, 0.7_fx);
  const Vec3 velocity{-1_fx, 0.5_fx, 2_fx};
  const Vec3 spin{0_fx, 3_fx, 0.125_fx};

  // In one go: everything in the definitions.
  World direct = make_world(WorldDef{.seed = 77});
  add(direct, {.type = BodyType::static_body, .shape = Shape::plane()});
  add(direct, {.shape = Shape::box({0.5_fx, 0.5_fx, 0.25_fx}),
               .position = position,
               .orientation = orientation,
               .linear_velocity = velocity,
               .angular_velocity = spin});
  add(direct, {.type = BodyType::kinematic,
               .shape = Shape::capsule(0.5_fx, 1_fx),
               .position = {5_fx, 5_fx, 5_fx}});

  // Step by step: defaults first, then the setters.
  World stepwise = make_world(WorldDef{.seed = 77});
  add(stepwise, {.type = BodyType::static_body, .shape = Shape::plane()});
  const BodyId box = add(stepwise, {.shape = Shape::box({0.5_fx, 0.5_fx, 0.25_fx})});
  const BodyId capsule = add(stepwise, {.shape = Shape::capsule(0.5_fx, 1_fx)});
  ASSERT_TRUE(stepwise.set_transform(box, position, orientation).ok());
  ASSERT_TRUE(stepwise.set_linear_velocity(box, velocity).ok());
  ASSERT_TRUE(stepwise.set_angular_velocity(box, spin).ok());
  ASSERT_TRUE(stepwise.set_transform(capsule, {5_fx, 5_fx, 5_fx}, Quat{}).ok());
  ASSERT_TRUE(stepwise.set_type(capsule, BodyType::kinematic).ok());

  // Restored from another world's bytes (a world with a different definition and seed).
  World restored = played_once(2, 60);
  ASSERT_TRUE(restored.restore(direct.save()).ok());

  EXPECT_EQ(stepwise.save(), direct.save());
  EXPECT_EQ(restored.save(), direct.save());
  EXPECT_EQ(stepwise.hashes(), direct.hashes());

  // And they stay identical when stepped.
  for (int f = 0; f < 90; ++f) {
    direct.step();
    stepwise.step();
    restored.step();
    ASSERT_EQ(stepwise.hashes(), direct.hashes()) << "frame " << f + 1;
    ASSERT_EQ(restored.hashes(), direct.hashes()) << "frame " << f + 1;
  }
  EXPECT_EQ(stepwise.save(), direct.save());
}

TEST(CanonicalBytes, TheIdCounterIsPartOfTheState) {
  // Equal bodies, but one world has issued an extra ID: their futures differ (the next body gets a
  // different ID), so their bytes must too.
  World a = playground(9);
  World b = playground(9);
  const BodyId extra = add(b, {.position = {50_fx, 50_fx, 50_fx}});
  ASSERT_TRUE(b.destroy_body(extra).ok());
  EXPECT_NE(a.save(), b.save());
  EXPECT_EQ(a.hashes().bodies, b.hashes().bodies);
  EXPECT_EQ(add(a, {}).value + 1, add(b, {}).value);
}

TEST(CanonicalBytes, SaveIsAPureFunctionOfTheState) {
  const World w = settled();
  const Bytes first = w.save();
  EXPECT_EQ(w.save(), first);
  const StateHashes h = w.hashes();
  EXPECT_EQ(w.save(), first);  // hashing does not disturb anything
  EXPECT_EQ(w.hashes(), h);
  World again;
  ASSERT_TRUE(again.restore(first).ok());
  ASSERT_TRUE(again.restore(again.save()).ok());
  EXPECT_EQ(again.save(), first);
}

}  // namespace
}  // namespace detsim

// Shared helpers of the world-state tests (sim_state_test.cpp, sim_state_restore_test.cpp,
// sim_state_codec_test.cpp): scenes built through the public API, the independent codec of the
// v2 state layout (state_codec.hpp) and what the world's accessors say its encoding must be, and
// the check that a refused restore changes nothing.
//
// It also replaces the global operator new with one that records the largest request (rule 7:
// sizes are validated before allocating), so include it from one file of a test executable only.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <initializer_list>
#include <map>
#include <new>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#define XXH_INLINE_ALL
#include <xxhash.h>

#include <detsim/core/bytes.hpp>
#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>
#include <detsim/sim/world.hpp>

#include "support/state_codec.hpp"
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
// The nothrow form too (std::stable_sort's buffer comes from it and goes back through the plain
// delete above): left to the runtime's, ASan reports a new/free mismatch.
[[gnu::noinline]] void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return ::operator new(size);
  } catch (...) {
    return nullptr;
  }
}
[[gnu::noinline]] void operator delete(void* p) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}

namespace detsim {

inline void PrintTo(const StateHashes& h, std::ostream* os) {
  *os << std::hex << "{total 0x" << h.total << ", globals 0x" << h.section("globals") << ", rng 0x"
      << h.section("rng") << ", bodies 0x" << h.section("bodies") << ", contacts 0x"
      << h.section("contacts") << "}" << std::dec;
}

namespace state_test {

using namespace detsim::literals;

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

// ---- The v2 codec and the world ----

/// A body as the world reports it, from its record and its set.
inline BodyState body_state(const DecodedSet& s, const DecodedBody& b) {
  BodyState out;
  out.id = b.id;
  out.type = s.type;
  out.shape = s.shape;
  out.position = b.position;
  out.orientation = b.orientation;
  out.linear_velocity = b.linear_velocity;
  out.angular_velocity = b.angular_velocity;
  out.mass = s.mass;
  out.inertia = s.inertia;
  out.friction = s.friction;
  out.restitution = s.restitution;
  out.linear_damping = s.linear_damping;
  out.angular_damping = s.angular_damping;
  out.layer = s.layer;
  out.mask = s.mask;
  out.sensor = (s.flags & kSensor) != 0;
  out.ccd = (s.flags & kCcd) != 0;
  out.user_data = b.user_data;
  out.awake = (b.flags & kAwake) != 0;
  out.sleep_time = b.sleep_time;
  out.force = b.force;
  out.torque = b.torque;
  return out;
}

inline BodyState body_state(const Decoded& d, std::size_t i) {
  return body_state(d.sets.at(static_cast<std::size_t>(d.bodies.at(i).set)), d.bodies[i]);
}

/// A contact as the world reports it (the used points only; the others stay zero).
inline ContactState contact_state(const DecodedContact& c) {
  ContactState out;
  out.a = BodyId{c.a};
  out.b = BodyId{c.b};
  out.point_count = static_cast<std::uint8_t>(c.point_count());
  out.touching = c.point_count() > 0;
  out.reported = c.reported();
  for (std::size_t p = 0; p < c.points.size() && p < out.points.size(); ++p) {
    const DecodedPoint& in = c.points[p];
    out.points[p].feature = std::uint32_t{feature_of_wire(in.feature_a)} |
                            (std::uint32_t{feature_of_wire(in.feature_b)} << 16U);
    out.points[p].normal_impulse = in.normal_impulse;
    out.points[p].tangent_impulse_1 = in.tangent_impulse_1;
    out.points[p].tangent_impulse_2 = in.tangent_impulse_2;
  }
  return out;
}

inline DecodedSet set_of(const BodyState& b) {
  DecodedSet s;
  s.type = b.type;
  s.shape = b.shape;
  s.mass = b.mass;
  s.inertia = b.inertia;
  s.friction = b.friction;
  s.restitution = b.restitution;
  s.linear_damping = b.linear_damping;
  s.angular_damping = b.angular_damping;
  s.layer = b.layer;
  s.mask = b.mask;
  s.flags = static_cast<std::uint8_t>((b.sensor ? kSensor : 0) | (b.ccd ? kCcd : 0));
  return s;
}

/// The body's record (ID step and set index left to the caller).
inline DecodedBody record_of(const BodyState& b) {
  DecodedBody r;
  r.id = b.id;
  r.flags = static_cast<std::uint8_t>(
      (b.awake ? kAwake : 0) | (b.user_data != 0 ? kHasUserData : 0) |
      (b.force != Vec3{} ? kHasForce : 0) | (b.torque != Vec3{} ? kHasTorque : 0));
  r.position = b.position;
  r.orientation = b.orientation;
  r.linear_velocity = b.linear_velocity;
  r.angular_velocity = b.angular_velocity;
  r.sleep_time = b.sleep_time;
  r.user_data = b.user_data;
  r.force = b.force;
  r.torque = b.torque;
  return r;
}

/// A joint's record as docs/STATE.md lays it out (the ID step is the caller's).
inline DecodedJoint joint_record(const JointState& j) {
  DecodedJoint r;
  r.type = static_cast<std::uint8_t>(j.def.type);
  r.body_a = j.def.body_a.value;
  r.body_b = j.def.body_b.value;
  r.flags = static_cast<std::uint8_t>(
      (j.def.limit_enabled ? kLimitEnabled : 0) | (j.def.motor_enabled ? kMotorEnabled : 0) |
      (j.def.collide_connected ? kCollideConnected : 0) | (j.broken ? kBroken : 0) |
      (j.def.user_data != 0 ? kJointHasUserData : 0));
  r.anchor = j.def.anchor;
  r.axis = j.def.axis;
  r.numbers = {j.def.limit_lower, j.def.limit_upper,      j.def.swing_limit,
               j.def.motor_speed, j.def.motor_max_force,  j.def.min_length,
               j.def.max_length,  j.def.spring_frequency, j.def.spring_damping_ratio,
               j.def.break_force, j.def.break_torque};
  r.local_anchor_a = j.local_anchor_a;
  r.local_anchor_b = j.local_anchor_b;
  r.local_axis_a = j.local_axis_a;
  r.local_axis_b = j.local_axis_b;
  r.relative_orientation = j.relative_orientation;
  r.length = j.length;
  r.linear_impulse = j.linear_impulse;
  r.angular_impulse = j.angular_impulse;
  r.axial_impulse = j.axial_impulse;
  r.motor_impulse = j.motor_impulse;
  r.limit_impulse = j.limit_impulse;
  r.user_data = j.def.user_data;
  return r;
}

/// What save() must write for `w`, built from body(), contacts(), joint() and the other
/// accessors: sets deduplicated in first-use order, flags from the values. The ID counters are not
/// public: the caller passes them.
inline Decoded expected_encoding(const World& w, std::uint32_t next_id,
                                 std::uint32_t next_joint_id = 1) {
  Decoded d;
  d.frame = w.frame();
  d.next_id = next_id;
  d.def = w.def();
  d.rng = w.rng().state();
  std::uint32_t previous_id = 0;
  for (const BodyId id : w.body_ids()) {
    const BodyState b = w.body(id).value();
    const DecodedSet s = set_of(b);
    const auto found = std::find_if(d.sets.begin(), d.sets.end(),
                                    [&](const DecodedSet& x) { return same_properties(x, s); });
    DecodedBody r = record_of(b);
    r.id_step = id.value - previous_id;
    r.set = static_cast<std::uint64_t>(found - d.sets.begin());
    if (found == d.sets.end()) d.sets.push_back(s);
    d.bodies.push_back(r);
    previous_id = id.value;
  }
  std::uint32_t previous_a = 0;
  for (const ContactState& c : w.contacts()) {
    DecodedContact out;
    out.a = c.a.value;
    out.b = c.b.value;
    out.a_step = c.a.value - previous_a;
    out.b_minus_a = c.b.value - c.a.value;
    out.points_byte = static_cast<std::uint8_t>(c.point_count | (c.reported ? kReported : 0));
    for (std::size_t p = 0; p < c.point_count && p < c.points.size(); ++p) {
      const ContactPointState& in = c.points[p];
      DecodedPoint point;
      point.feature_a = wire_feature(static_cast<std::uint16_t>(in.feature & 0xFFFFU));
      point.feature_b = wire_feature(static_cast<std::uint16_t>(in.feature >> 16U));
      point.normal_impulse = in.normal_impulse;
      point.tangent_impulse_1 = in.tangent_impulse_1;
      point.tangent_impulse_2 = in.tangent_impulse_2;
      out.points.push_back(point);
    }
    d.contacts.push_back(out);
    previous_a = c.a.value;
  }
  d.next_joint_id = next_joint_id;
  std::uint32_t previous_joint = 0;
  for (const JointId id : w.joint_ids()) {
    DecodedJoint r = joint_record(w.joint(id).value());
    r.id_step = id.value - previous_joint;
    previous_joint = id.value;
    d.joints.push_back(r);
  }
  return d;
}

inline std::uint64_t xxh3(std::span<const std::uint8_t> bytes) {
  return XXH3_64bits(bytes.data(), bytes.size());
}

/// body_hash(id) as docs/STATE.md defines it: the body's set, then its record as if it were the
/// only body (ID step = its ID, set index 0).
inline std::uint64_t expected_body_hash(const Decoded& d, std::size_t i) {
  DecodedBody alone = d.bodies.at(i);
  alone.id_step = alone.id.value;
  alone.set = 0;
  Bytes bytes = encode_set(d.sets.at(static_cast<std::size_t>(d.bodies[i].set)));
  const Bytes record = encode_body(alone);
  bytes.insert(bytes.end(), record.begin(), record.end());
  return xxh3(bytes);
}

inline bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// Whether `message` names the byte of one of `offsets` (docs/STATE.md: "the message names the
/// byte offset and the field"; the offset of the record the field is in is accepted too).
inline bool names_one_of(const std::string& message, std::initializer_list<std::size_t> offsets) {
  return std::any_of(offsets.begin(), offsets.end(), [&](std::size_t at) {
    return contains(message, "byte " + std::to_string(at));
  });
}

/// Whether `text` has the number `n` as a whole decimal token.
inline bool mentions_number(const std::string& text, std::uint64_t n) {
  const std::string digits = std::to_string(n);
  for (std::size_t at = text.find(digits); at != std::string::npos;
       at = text.find(digits, at + 1)) {
    const bool starts = at == 0 || text[at - 1] < '0' || text[at - 1] > '9';
    const std::size_t after = at + digits.size();
    const bool ends = after == text.size() || text[after] < '0' || text[after] > '9';
    if (starts && ends) return true;
  }
  return false;
}

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

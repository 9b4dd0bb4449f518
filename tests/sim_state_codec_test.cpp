// World state, what version 2 of the encoding adds (docs/STATE.md): canonical LEB128 vars,
// property sets written once in first-use order, body flags for the values that follow, ID and
// contact steps, the point byte and the features. Checked with the test's own codec
// (support/state_codec.hpp):
//
// - restore() refuses every non-canonical or impossible form with a message naming the byte, and
//   leaves the world as it was;
// - bytes it accepts save back unchanged, including the extremes of every var;
// - what is shared or zero is not written: the structural facts a smaller encoding rests on.
//
// Worlds are built through the public API only.
#include <array>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/state_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;
using namespace detsim::state_test;

// N identical boxes resting side by side (on a plane if asked), not stepped.
World boxes(int n, bool on_plane) {
  World w = make_world(WorldDef{});
  if (on_plane) add(w, {.type = BodyType::static_body, .shape = Shape::plane()});
  for (int i = 0; i < n; ++i) {
    add(w,
        {.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx}),
         .position = {Fixed::from_int(i % 10) * 1.5_fx, 0.5_fx, Fixed::from_int(i / 10) * 1.5_fx}});
  }
  return w;
}

// The value of the (canonical) var at `at`.
std::uint64_t var_at(std::span<const std::uint8_t> bytes, std::size_t at) {
  StateReader r(bytes.subspan(at));
  const std::uint64_t v = r.var("var", 64);
  EXPECT_TRUE(r.ok()) << r.error();
  return v;
}

// ======================================================================================
// The codec itself
// ======================================================================================

TEST(StateCodec, Leb128AndZigzag) {
  EXPECT_EQ(leb128(0), Bytes{0x00});
  EXPECT_EQ(leb128(127), Bytes{0x7F});
  EXPECT_EQ(leb128(128), (Bytes{0x80, 0x01}));
  EXPECT_EQ(leb128(300), (Bytes{0xAC, 0x02}));
  EXPECT_EQ(leb128(1, 3), (Bytes{0x81, 0x80, 0x00}));  // overlong
  EXPECT_EQ(leb128(0xFFFFFFFFU), (Bytes{0xFF, 0xFF, 0xFF, 0xFF, 0x0F}));
  EXPECT_EQ(leb128(std::numeric_limits<std::uint64_t>::max()).size(), 10U);
  EXPECT_EQ(leb128(std::numeric_limits<std::uint64_t>::max()).back(), 0x01);
  EXPECT_EQ(zigzag(Fixed{}), 0U);
  EXPECT_EQ(zigzag(-Fixed::epsilon()), 1U);
  EXPECT_EQ(zigzag(Fixed::epsilon()), 2U);
  EXPECT_EQ(zigzag(Fixed::min()), std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(zigzag(Fixed::max()), std::numeric_limits<std::uint64_t>::max() - 1);
  for (const Fixed f : {Fixed{}, Fixed::one(), -Fixed::one(), Fixed::min(), Fixed::max(), -2.5_fx})
    EXPECT_EQ(unzigzag(zigzag(f)), f);
  EXPECT_EQ(vfixed_size(Fixed::one()), 5U);  // 2^33
  EXPECT_EQ(wire_feature(0x0305), 5U * 4 + 3);
  EXPECT_EQ(feature_of_wire(5U * 4 + 3), 0x0305);
  EXPECT_EQ(wire_feature(0x03FF), 1023U);
}

TEST(StateCodec, DecodeThenEncodeGivesTheSameBytes) {
  std::vector<World> worlds;
  worlds.emplace_back();
  worlds.push_back(playground(1));
  worlds.push_back(played_once(2, 60));
  worlds.push_back(settled());
  World pile = boxes(30, true);
  run(pile, 30);
  worlds.push_back(pile);
  for (std::size_t i = 0; i < worlds.size(); ++i) {
    SCOPED_TRACE(testing::Message() << "world " << i);
    const Bytes bytes = worlds[i].save();
    const Decoded d = decode(bytes);
    ASSERT_TRUE(d.ok) << d.error;
    EXPECT_EQ(d.end, bytes.size());
    EXPECT_TRUE(encode(d) == bytes);
  }
}

// ======================================================================================
// What restore() refuses
// ======================================================================================

class CanonicalRestore : public testing::Test {
 protected:
  void SetUp() override {
    state_ = settled().save();
    decoded_ = decode(state_);
    ASSERT_TRUE(decoded_.ok) << decoded_.error;
    ASSERT_GE(decoded_.contacts.size(), 3U);
    target_ = played_once(22, 120);
  }

  // `bad` must be refused, with a message naming the field's byte or its record's.
  void expect_refused_at(const Bytes& bad, std::initializer_list<std::size_t> field_or_record,
                         const std::string& what) {
    SCOPED_TRACE(what);
    const std::string message = expect_rejected(target_, bad);
    EXPECT_TRUE(names_one_of(message, field_or_record)) << what << ": " << message;
  }

  // Replaces the var at `at` (in a section's payload) with `with`, keeping that section's length
  // right: a var of another length must be refused for what it is, not for the container.
  void replace_in_payload(Bytes& bytes, std::size_t at, const Bytes& with) const {
    const auto delta = static_cast<std::ptrdiff_t>(with.size()) -
                       static_cast<std::ptrdiff_t>(var_length_at(bytes, at));
    replace_var(bytes, at, with);
    adjust_section_length(bytes, decoded_, at, delta);
  }

  // `bytes` must be accepted and saved back unchanged.
  void expect_accepted(const Bytes& bytes, const std::string& what) {
    World w;
    const Status st = w.restore(bytes);
    ASSERT_TRUE(st.ok()) << what << ": " << st.message();
    EXPECT_TRUE(w.save() == bytes) << what << ": save() does not give the same bytes back";
  }

  Bytes state_;
  Decoded decoded_;
  World target_;
};

// A var in a real state: where it is, the record it is in, what it is.
struct VarField {
  std::size_t at;
  std::size_t record_at;
  std::string what;
};

TEST_F(CanonicalRestore, OverlongVars) {
  // Every kind of var, one byte longer than its shortest form (a last byte of zero).
  const DecodedBody& sphere = decoded_.bodies[1];
  const DecodedBody& with_user_data = decoded_.bodies[2];
  ASSERT_EQ(with_user_data.flags & kHasUserData, kHasUserData);
  ASSERT_EQ(with_user_data.flags & (kHasForce | kHasTorque), 0);
  const DecodedContact& contact = decoded_.contacts.back();
  ASSERT_GT(decoded_.contacts[0].point_count(), 0U);
  const DecodedPoint& point = decoded_.contacts[0].points[0];
  const DecodedContact& first = decoded_.contacts[0];
  const std::vector<VarField> vars{
      {sphere.at, sphere.at, "body ID step"},
      {sphere.set_at, sphere.at, "property set index"},
      {sphere.position_at, sphere.at, "position x (vfixed)"},
      {decoded_.bodies[0].linear_velocity_at, decoded_.bodies[0].at, "a zero linear velocity x"},
      {with_user_data.end - var_size(with_user_data.user_data), with_user_data.at, "user data"},
      {decoded_.sets[1].mass_at, decoded_.sets[1].at, "mass"},
      {contact.at, contact.at, "contact a step"},
      {contact.b_at, contact.at, "contact b - a"},
      {point.at, first.at, "feature on a"},
      {point.feature_b_at, first.at, "feature on b"},
      {point.normal_impulse_at, first.at, "normal impulse"},
  };
  for (const VarField& v : vars) {
    const std::uint64_t value = var_at(state_, v.at);
    const std::size_t shortest = var_size(value);
    ASSERT_EQ(var_length_at(state_, v.at), shortest) << v.what;
    for (const std::size_t length : {shortest + 1, shortest + 2}) {
      Bytes bad = state_;
      replace_in_payload(bad, v.at, leb128(value, length));
      expect_refused_at(bad, {v.at, v.record_at}, v.what + " in " + std::to_string(length));
    }
  }
  // Zero as {0x80, 0x00}, the shortest overlong form.
  Bytes bad = state_;
  const std::size_t zero_at = decoded_.bodies[0].linear_velocity_at;
  ASSERT_EQ(state_[zero_at], 0);
  replace_in_payload(bad, zero_at, Bytes{0x80, 0x00});
  expect_refused_at(bad, {zero_at, decoded_.bodies[0].at}, "zero in two bytes");
}

TEST_F(CanonicalRestore, VarsBeyondTheirField) {
  // 32-bit fields: a 5-byte var whose value needs 33 to 35 bits, and a 6-byte var.
  const DecodedBody& sphere = decoded_.bodies[1];
  const DecodedContact& contact = decoded_.contacts.back();
  const DecodedPoint& point = decoded_.contacts[0].points.at(0);
  const std::size_t first_at = decoded_.contacts[0].at;
  const std::vector<VarField> fields32{
      {sphere.at, sphere.at, "body ID step"},     {sphere.set_at, sphere.at, "property set index"},
      {contact.at, contact.at, "contact a step"}, {contact.b_at, contact.at, "contact b - a"},
      {point.at, first_at, "feature on a"},       {point.feature_b_at, first_at, "feature on b"},
  };
  for (const VarField& v : fields32) {
    for (const std::uint64_t value :
         {std::uint64_t{1} << 32, (std::uint64_t{1} << 32) + var_at(state_, v.at),
          (std::uint64_t{1} << 35) - 1}) {
      Bytes bad = state_;
      replace_in_payload(bad, v.at, leb128(value));
      ASSERT_EQ(leb128(value).size(), 5U);
      expect_refused_at(bad, {v.at, v.record_at}, v.what + " = " + std::to_string(value));
    }
    Bytes bad = state_;
    replace_in_payload(bad, v.at,
                       leb128(std::uint64_t{1} << 35));  // 6 bytes, canonical but too long
    expect_refused_at(bad, {v.at, v.record_at}, v.what + " in 6 bytes");
  }
  // 64-bit fields: 11 bytes (overlong, and with a value beyond 64 bits), and a 10-byte var whose
  // last byte carries more than bit 63.
  const DecodedBody& with_user_data = decoded_.bodies[2];
  const std::vector<VarField> fields64{
      {sphere.position_at, sphere.at, "position x"},
      {with_user_data.end - var_size(with_user_data.user_data), with_user_data.at, "user data"},
      {point.normal_impulse_at, first_at, "normal impulse"},
  };
  for (const VarField& v : fields64) {
    const std::vector<Bytes> forms{
        leb128(var_at(state_, v.at), 11),
        Bytes{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x01},
        Bytes{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x02},
        Bytes{0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x7F},
    };
    for (std::size_t i = 0; i < forms.size(); ++i) {
      Bytes bad = state_;
      replace_in_payload(bad, v.at, forms[i]);
      expect_refused_at(bad, {v.at, v.record_at}, v.what + ", form " + std::to_string(i));
    }
  }
}

// Removes set `k`, its bodies taking set `instead` (an index before k); later indices move down.
void merge_set(Decoded& d, std::size_t k, std::size_t instead) {
  for (DecodedBody& b : d.bodies) {
    if (b.set == k) b.set = instead;
    if (b.set > k) --b.set;
  }
  d.sets.erase(d.sets.begin() + static_cast<std::ptrdiff_t>(k));
}

TEST_F(CanonicalRestore, PropertySetsMustBeDistinct) {
  // The two lower stacked boxes share a set; the top one differs only in CCD.
  const auto lower = static_cast<std::size_t>(decoded_.bodies[4].set);
  const auto top = static_cast<std::size_t>(decoded_.bodies[6].set);
  ASSERT_EQ(decoded_.bodies[5].set, lower);
  ASSERT_NE(top, lower);
  ASSERT_EQ(decoded_.sets[top].flags, kCcd);
  Decoded d = decoded_;
  d.sets[top].flags = 0;  // now a duplicate of `lower`
  expect_refused_at(encode(d), {decoded_.sets[top].at}, "a duplicate set");
  // The same world written with one set for the three boxes is fine.
  merge_set(d, top, lower);
  expect_accepted(encode(d), "the duplicate merged");
}

TEST_F(CanonicalRestore, PropertySetsInFirstUseOrderAndEachUsed) {
  // Sets 0 and 1 swapped, and the bodies' indices with them: the same world, another order.
  Decoded d = decoded_;
  std::swap(d.sets[0], d.sets[1]);
  for (DecodedBody& b : d.bodies) {
    if (b.set <= 1) b.set = 1 - b.set;
  }
  expect_refused_at(encode(d),
                    {decoded_.bodies[0].at, decoded_.bodies[0].set_at, decoded_.sets[0].at},
                    "sets 0 and 1 swapped");

  // An unused set at the end (distinct from the others).
  d = decoded_;
  DecodedSet unused = d.sets[1];
  unused.friction += Fixed::epsilon();
  d.sets.push_back(unused);
  expect_rejected(target_, encode(d));

  // An unused set in the middle (the later indices moved past it).
  d = decoded_;
  d.sets.insert(d.sets.begin() + 2, unused);
  for (DecodedBody& b : d.bodies) {
    if (b.set >= 2) ++b.set;
  }
  expect_rejected(target_, encode(d));
}

TEST_F(CanonicalRestore, SetIndexOutOfRange) {
  // A plane and three identical boxes: every set is in use before the last body, so its index
  // may be 0 or 1 only.
  const Bytes bytes = boxes(3, true).save();
  const Decoded base = decode(bytes);
  ASSERT_TRUE(base.ok) << base.error;
  ASSERT_EQ(base.sets.size(), 2U);
  for (const std::uint64_t index :
       {std::uint64_t{2}, std::uint64_t{3}, std::uint64_t{1000}, std::uint64_t{0xFFFFFFFFU}}) {
    Decoded d = base;
    d.bodies.back().set = index;
    expect_refused_at(encode(d), {base.bodies.back().at, base.bodies.back().set_at},
                      "index " + std::to_string(index));
  }
  // The first body's index must be 0, the first use of set 0.
  Decoded d = base;
  d.bodies[0].set = 1;
  expect_refused_at(encode(d), {base.bodies[0].at, base.bodies[0].set_at},
                    "the first body's index 1");
  expect_accepted(encode(base), "the real indices");
}

TEST_F(CanonicalRestore, UnknownFlagBits) {
  const DecodedBody& sphere = decoded_.bodies[1];
  for (const int bit : {0x10, 0x20, 0x40, 0x80}) {
    Decoded d = decoded_;
    d.bodies[1].flags = static_cast<std::uint8_t>(sphere.flags | bit);
    expect_refused_at(encode(d), {sphere.at, sphere.flags_at},
                      "body flag bit " + std::to_string(bit));
  }
}

// Every bit of a property set's flags has a meaning: sensor, CCD, then the six axis locks in
// order (translation x, y, z, rotation x, y, z). Each lock bit restores as that lock alone.
TEST_F(CanonicalRestore, PropertyFlagBitsAreTheLocks) {
  const DecodedBody& sphere = decoded_.bodies[1];
  const DecodedSet& set = decoded_.sets[static_cast<std::size_t>(sphere.set)];
  ASSERT_EQ(set.flags & ~(kSensor | kCcd), 0);
  for (int k = 0; k < 6; ++k) {
    Decoded d = decoded_;
    d.sets[static_cast<std::size_t>(sphere.set)].flags =
        static_cast<std::uint8_t>(set.flags | (kLockTranslationX << k));
    expect_accepted(encode(d), "lock bit " + std::to_string(k));
    World w;
    ASSERT_TRUE(w.restore(encode(d)).ok());
    const auto b = w.body(w.body_ids()[1]);
    ASSERT_TRUE(b.ok()) << b.message();
    const std::array<bool, 6> locks{b->lock_translation_x, b->lock_translation_y,
                                    b->lock_translation_z, b->lock_rotation_x,
                                    b->lock_rotation_y,    b->lock_rotation_z};
    for (int m = 0; m < 6; ++m)
      EXPECT_EQ(locks[static_cast<std::size_t>(m)], m == k) << "bit " << k << ", lock " << m;
  }
}

TEST_F(CanonicalRestore, FlaggedValuesAreNotZero) {
  const DecodedBody& sphere = decoded_.bodies[1];
  ASSERT_EQ(sphere.flags & (kHasUserData | kHasForce | kHasTorque), 0);
  for (const std::uint8_t bit : {kHasUserData, kHasForce, kHasTorque}) {
    Decoded d = decoded_;
    d.bodies[1].flags = static_cast<std::uint8_t>(sphere.flags | bit);
    // The flag's byte, the zero value's (where the record used to end) or the record's.
    expect_refused_at(encode(d), {sphere.at, sphere.flags_at, sphere.end},
                      "flag " + std::to_string(bit) + " with a zero value");
  }
  // With values that are not zero, the same bits are fine (the world then has a force and a
  // torque pending and user data).
  Decoded d = decoded_;
  d.bodies[1].flags |= kHasUserData | kHasForce | kHasTorque;
  d.bodies[1].user_data = 1;
  d.bodies[1].force = {Fixed{}, -Fixed::epsilon(), Fixed{}};
  d.bodies[1].torque = {Fixed{}, Fixed{}, 3_fx};
  expect_accepted(encode(d), "non-zero flagged values");
}

TEST_F(CanonicalRestore, FeaturesBeyondTheirRange) {
  // A feature is index * 4 + kind with a 14-bit index: at most 65535.
  const DecodedContact& contact = decoded_.contacts[0];
  ASSERT_GT(contact.point_count(), 0U);
  for (const std::uint64_t feature : {std::uint64_t{65536}, std::uint64_t{65539},
                                      std::uint64_t{0x7FFFF}, std::uint64_t{0xFFFFFFFF}}) {
    Decoded d = decoded_;
    d.contacts[0].points[0].feature_a = feature;
    expect_refused_at(encode(d), {contact.at, contact.points[0].at},
                      "feature on a " + std::to_string(feature));
    d = decoded_;
    d.contacts[0].points.back().feature_b = feature;
    expect_refused_at(encode(d), {contact.at, contact.points.back().feature_b_at},
                      "feature on b " + std::to_string(feature));
  }
}

TEST_F(CanonicalRestore, AcceptedExtremesSaveTheSameBytes) {
  // The canonical encoding both ways: what restore accepts, save writes back byte for byte, at
  // the limits of every var.
  Decoded d = decoded_;
  d.bodies[2].user_data = std::numeric_limits<std::uint64_t>::max();  // a 10-byte var
  expect_accepted(encode(d), "user data 2^64 - 1");

  // The highest ID there can be (the counter at 2^32 - 1): a 5-byte ID step, and the contacts of
  // that body follow it.
  d = decoded_;
  const std::uint32_t old_id = d.bodies.back().id.value;
  const std::uint32_t new_id = 0xFFFFFFFEU;
  d.next_id = 0xFFFFFFFFU;
  d.bodies.back().id_step += new_id - old_id;
  for (DecodedContact& c : d.contacts) {
    if (c.b == old_id) c.b_minus_a += new_id - old_id;
  }
  expect_accepted(encode(d), "body ID 2^32 - 2");

  // Extreme impulses (10-byte vfixed), a feature of 1023, and a contact with no points.
  d = decoded_;
  DecodedPoint& p = d.contacts[0].points[0];
  p.tangent_impulse_1 = Fixed::min();
  p.tangent_impulse_2 = Fixed::max();
  p.feature_a = 1023;
  d.contacts[1].points.clear();
  d.contacts[1].points_byte = 0;
  expect_accepted(encode(d), "extreme impulses, feature 1023, no points");
}

// ======================================================================================
// What is not written
// ======================================================================================

TEST(StateSize, IdenticalBodiesShareOneSet) {
  const Decoded alone = decode(boxes(100, false).save());
  ASSERT_TRUE(alone.ok) << alone.error;
  ASSERT_EQ(alone.bodies.size(), 100U);
  EXPECT_EQ(alone.sets.size(), 1U);
  for (const DecodedBody& b : alone.bodies) {
    EXPECT_EQ(b.set, 0U);
    EXPECT_EQ(b.id_step, 1U);
    EXPECT_EQ(b.set_at - b.at, 1U);  // one-byte ID steps and set indices
  }

  World w = boxes(100, true);
  run(w, 30);
  const Decoded pile = decode(w.save());
  ASSERT_TRUE(pile.ok) << pile.error;
  EXPECT_EQ(pile.sets.size(), 2U);
  for (std::size_t i = 1; i < pile.bodies.size(); ++i)
    EXPECT_EQ(pile.bodies[i].set, 1U);
  // Every box rests on the plane with four points; each feature is one byte.
  ASSERT_EQ(pile.contacts.size(), 100U);
  for (const DecodedContact& c : pile.contacts) {
    EXPECT_EQ(c.point_count(), 4U) << c.a << "-" << c.b;
    for (const DecodedPoint& p : c.points) {
      EXPECT_EQ(p.feature_b_at - p.at, 1U);
      EXPECT_EQ(p.normal_impulse_at - p.feature_b_at, 1U);
    }
  }

  // Switching a box between kinematic and dynamic changes its set, and switching back shares
  // again.
  World switched = boxes(5, false);
  ASSERT_TRUE(switched.set_type(BodyId{3}, BodyType::kinematic).ok());
  Decoded d = decode(switched.save());
  ASSERT_TRUE(d.ok) << d.error;
  EXPECT_EQ(d.sets.size(), 2U);
  EXPECT_EQ(d.bodies[2].set, 1U);
  EXPECT_EQ(d.bodies[3].set, 0U);
  ASSERT_TRUE(switched.set_type(BodyId{3}, BodyType::dynamic).ok());
  d = decode(switched.save());
  ASSERT_TRUE(d.ok) << d.error;
  EXPECT_EQ(d.sets.size(), 1U);
}

// The length a body record must have: its vars at their shortest, the flagged values only.
std::size_t record_length(const DecodedBody& b) {
  std::size_t n = var_size(b.id_step) + var_size(b.set) + 1 + vec3_size(b.position) +
                  quat_size(b.orientation) + vec3_size(b.linear_velocity) +
                  vec3_size(b.angular_velocity) + vfixed_size(b.sleep_time);
  if (b.user_data != 0) n += var_size(b.user_data);
  if (b.force != Vec3{}) n += vec3_size(b.force);
  if (b.torque != Vec3{}) n += vec3_size(b.torque);
  return n;
}

TEST(StateSize, AbsentValuesAreNotWritten) {
  // A body at rest at the origin: ID step, set and flags (1 byte each), position 3, orientation 8
  // (w = 1 is 2^33 zigzagged: 5 bytes), velocities 6, sleep time 1.
  World w = make_world(WorldDef{});
  add(w, {.type = BodyType::static_body, .shape = Shape::box({1_fx, 1_fx, 1_fx})});
  add(w, {});
  Decoded d = decode(w.save());
  ASSERT_TRUE(d.ok) << d.error;
  ASSERT_EQ(d.bodies.size(), 2U);
  EXPECT_EQ(d.bodies[0].flags, 0);
  EXPECT_EQ(d.bodies[1].flags, kAwake);
  for (const DecodedBody& b : d.bodies)
    EXPECT_EQ(b.end - b.at, 21U) << "body " << b.id.value;

  // A force is written while pending (here 0, 1, 0: 1 + 5 + 1 bytes), and then no longer.
  ASSERT_TRUE(w.apply_force(BodyId{2}, {0_fx, 1_fx, 0_fx}).ok());
  d = decode(w.save());
  ASSERT_TRUE(d.ok) << d.error;
  EXPECT_EQ(d.bodies[1].flags, kAwake | kHasForce);
  EXPECT_EQ(d.bodies[1].end - d.bodies[1].at, 21U + 1 + 5 + 1);
  w.step();
  d = decode(w.save());
  ASSERT_TRUE(d.ok) << d.error;
  EXPECT_EQ(d.bodies[1].flags, kAwake);

  // In a played scene, every record is exactly the length of its fields, and a value is flagged
  // exactly when it is not zero.
  World played_world = played_once(2, 60);
  ASSERT_TRUE(played_world.apply_torque(BodyId{5}, {0_fx, 1_fx, 0_fx}).ok());
  ASSERT_TRUE(played_world.apply_force(BodyId{6}, {-0.25_fx, 0_fx, 7_fx}).ok());
  d = decode(played_world.save());
  ASSERT_TRUE(d.ok) << d.error;
  for (std::size_t i = 0; i < d.bodies.size(); ++i) {
    const DecodedBody& b = d.bodies[i];
    const BodyState state = played_world.body(b.id).value();
    EXPECT_EQ(b.end - b.at, record_length(b)) << "body " << b.id.value;
    EXPECT_EQ((b.flags & kHasUserData) != 0, state.user_data != 0) << "body " << b.id.value;
    EXPECT_EQ((b.flags & kHasForce) != 0, state.force != Vec3{}) << "body " << b.id.value;
    EXPECT_EQ((b.flags & kHasTorque) != 0, state.torque != Vec3{}) << "body " << b.id.value;
  }
  EXPECT_EQ(d.bodies[4].flags & kHasTorque, kHasTorque);
  EXPECT_EQ(d.bodies[5].flags & kHasForce, kHasForce);
  EXPECT_EQ(d.bodies[2].flags & kHasUserData, kHasUserData);

  // A contact is its two steps, its point byte and its points, nothing else.
  for (const DecodedContact& c : d.contacts) {
    std::size_t n = var_size(c.a_step) + var_size(c.b_minus_a) + 1;
    for (const DecodedPoint& p : c.points) {
      n += var_size(p.feature_a) + var_size(p.feature_b) + vfixed_size(p.normal_impulse) +
           vfixed_size(p.tangent_impulse_1) + vfixed_size(p.tangent_impulse_2);
    }
    EXPECT_EQ(c.end - c.at, n) << c.a << "-" << c.b;
  }
}

}  // namespace
}  // namespace detsim

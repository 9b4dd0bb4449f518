// World state: restore() refuses corrupt, truncated and hostile bytes with a message naming the
// byte, and a refused restore leaves the world exactly as it was (its save() bytes and hashes are
// compared before and after every rejected restore). Docs/DETERMINISM.md rule 7.
//
// Bad states are made by decoding a real one with the test's own v2 codec
// (support/state_codec.hpp), changing one field and encoding it again; what version 2 newly refuses
// (non-canonical vars, property sets, flag bits, features) is in sim_state_v2_codec_test.cpp.
//
// Worlds are built through the public API only.
#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "sim/src/shapes.hpp"
#include "support/state_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;
using namespace detsim::state_test;

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
  // The header: magic, version, globals, RNG and the property-set count.
  const std::size_t header = decoded_.property_count_at + 4;
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
  // Magic, version and the property-set count can never flip to a valid state; the frame number,
  // the seed and most of the RNG state always do.
  EXPECT_GT(accepted, 64U * 3);
  EXPECT_LT(accepted, header * 8 - (4 + 4 + 4) * 8);
}

TEST_F(RejectedRestore, BitFlipsAcrossBodiesAndContacts) {
  // Every bit of every property-set byte, of the first three body records (a plane, a sphere and
  // a box) and of every contact byte, and every bit of every third byte of the other bodies (the
  // sampled phase shifts from body to body with their lengths).
  std::vector<std::size_t> positions;
  const std::size_t dense_until = decoded_.bodies[3].at;
  for (std::size_t at = decoded_.property_count_at + 4; at < decoded_.contact_count_at; ++at) {
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
  const auto real_until = [&](std::size_t end) {
    return Bytes(state_.begin(), state_.begin() + static_cast<std::ptrdiff_t>(end));
  };
  const Bytes header = real_until(decoded_.property_count_at);
  const Bytes with_sets = real_until(decoded_.body_count_at);
  for (int i = 0; i < 10000; ++i) {
    Bytes junk(rng.below(600));
    for (std::uint8_t& b : junk)
      b = static_cast<std::uint8_t>(rng.next_u64());
    // A quarter plain junk, a quarter behind a valid magic and version, a quarter behind a real
    // header (the property-set reader sees garbage) and a quarter behind the real header and sets
    // (the body and contact readers see garbage too).
    const Bytes* before = i % 4 == 1   ? &prefix
                          : i % 4 == 2 ? &header
                          : i % 4 == 3 ? &with_sets
                                       : nullptr;
    if (before != nullptr) junk.insert(junk.begin(), before->begin(), before->end());
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
  // The bytes of a real state up to one of its counts (property sets, bodies, contacts), then a
  // hostile count and a handful of bytes.
  for (const std::size_t count_at :
       {decoded_.property_count_at, decoded_.body_count_at, decoded_.contact_count_at}) {
    for (const std::uint32_t count : {0xFFFFFFFFU, 0x10000000U, 0x01000000U, 100000U, 5U}) {
      Bytes hostile(state_.begin(), state_.begin() + static_cast<std::ptrdiff_t>(count_at));
      hostile.resize(hostile.size() + 4 + 64, 0x01);
      put_u32(hostile, count_at, count);
      g_largest_allocation = 0;
      const std::string message = expect_rejected(target_, hostile);
      EXPECT_LT(g_largest_allocation.load(), std::size_t{64} * 1024 + state_.size() * 4)
          << "count " << count << " at byte " << count_at << ": largest allocation "
          << g_largest_allocation.load() << " (" << message << ")";
    }
  }
  // A count just within what the bytes could hold if bodies were as small as a body can be (17
  // bytes: ID step, set, flags and 14 one-byte vfixed): the allocation stays proportional to the
  // input. (A body held in memory is some 300 bytes, 18 times its smallest encoding: the bound
  // allows that factor, not one that grows with the count.)
  Bytes padded(state_.begin(),
               state_.begin() + static_cast<std::ptrdiff_t>(decoded_.body_count_at));
  padded.resize(padded.size() + 4 + 100000, 0x00);
  put_u32(padded, decoded_.body_count_at, 100000U / 17);
  g_largest_allocation = 0;
  expect_rejected(target_, padded);
  EXPECT_LT(g_largest_allocation.load(), padded.size() * 32);
}

TEST_F(RejectedRestore, WrongMagicOrVersion) {
  Bytes bad = state_;
  bad[0] = 'X';
  std::string message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "magic")) << message;

  // Another version, the earlier ones included, is refused with both version numbers in the
  // message.
  for (const std::uint32_t version :
       {0U, 1U, kStateVersion - 1, kStateVersion + 1, 0xFFFFFFFFU, 0x01000000U}) {
    bad = state_;
    put_u32(bad, 4, version);
    message = expect_rejected(target_, bad);
    EXPECT_TRUE(contains(message, "version")) << message;
    EXPECT_TRUE(mentions_number(message, version)) << message;
    EXPECT_TRUE(mentions_number(message, kStateVersion)) << message;
  }
  expect_rejected(target_, Bytes{'D', 'S', 'I', 'M'});
  expect_rejected(target_, Bytes{});
}

TEST_F(RejectedRestore, BodyIdsMustBeAscendingUniqueAndKnown) {
  ASSERT_GE(decoded_.bodies.size(), 3U);
  const DecodedBody& last = decoded_.bodies.back();

  Decoded d = decoded_;
  d.bodies[1].id_step = 0;  // a duplicate of the first ID
  std::string message = expect_rejected(target_, encode(d));
  EXPECT_TRUE(contains(message, "byte " + std::to_string(decoded_.bodies[1].at))) << message;

  d = decoded_;
  d.bodies[0].id_step = 0;  // the null ID
  message = expect_rejected(target_, encode(d));
  EXPECT_TRUE(contains(message, "byte " + std::to_string(decoded_.bodies[0].at))) << message;

  d = decoded_;
  d.bodies.back().id_step += decoded_.next_id - last.id.value;  // not yet issued
  expect_rejected(target_, encode(d));

  // Steps whose sum passes 2^32 - 1: to exactly 2^32 (0 in 32 bits) and beyond.
  const std::uint64_t before_last = last.id.value - last.id_step;
  for (const std::uint64_t step :
       {(std::uint64_t{1} << 32) - before_last, (std::uint64_t{1} << 32) - before_last + 1,
        std::uint64_t{0xFFFFFFFFU}}) {
    d = decoded_;
    d.bodies.back().id_step = step;
    message = expect_rejected(target_, encode(d));
    EXPECT_TRUE(contains(message, "byte " + std::to_string(last.at))) << message;
  }
}

TEST_F(RejectedRestore, UnknownShapeOrBodyType) {
  const auto sphere_set = static_cast<std::size_t>(decoded_.bodies[1].set);
  ASSERT_EQ(decoded_.sets[sphere_set].shape.type, ShapeType::sphere);
  // 0, the first value past the table of kinds (7 became the triangle mesh; new types keep
  // moving it), and two far ones.
  const auto past_last = static_cast<std::uint8_t>(sim_detail::shape_kinds().back()->type) + 1;
  for (const std::uint8_t type : {std::uint8_t{0}, static_cast<std::uint8_t>(past_last),
                                  std::uint8_t{0x80}, std::uint8_t{0xFF}}) {
    Decoded d = decoded_;
    d.sets[sphere_set].shape.type = static_cast<ShapeType>(type);
    d.sets[sphere_set].shape.radius = Fixed{};
    const std::string message = expect_rejected(target_, encode(d));
    EXPECT_TRUE(contains(message, "shape type")) << message;
    const std::size_t set_at = decoded_.sets[sphere_set].at;
    EXPECT_TRUE(names_one_of(message, {set_at, set_at + 1}))
        << "set at byte " << set_at << ", "
        << "shape type at " << set_at + 1 << ": " << message;
  }
  for (const std::uint8_t type : {std::uint8_t{3}, std::uint8_t{0xFF}}) {
    Decoded d = decoded_;
    d.sets[sphere_set].type = static_cast<BodyType>(type);
    const std::string message = expect_rejected(target_, encode(d));
    EXPECT_TRUE(contains(message, "type")) << message;
    // The type is the set's first byte.
    EXPECT_TRUE(names_one_of(message, {decoded_.sets[sphere_set].at}))
        << "set at byte " << decoded_.sets[sphere_set].at << ": " << message;
  }
  // A dynamic plane.
  ASSERT_EQ(decoded_.sets[0].shape.type, ShapeType::plane);
  Decoded d = decoded_;
  d.sets[0].type = BodyType::dynamic;
  expect_rejected(target_, encode(d));
}

TEST_F(RejectedRestore, NonUnitQuaternion) {
  const DecodedBody& sphere = decoded_.bodies[1];
  for (const std::int64_t w : {std::int64_t{0}, 2 * Fixed::one_raw, -(std::int64_t{1} << 62)}) {
    Decoded d = decoded_;
    d.bodies[1].orientation = Quat{Fixed::from_raw(w), Fixed{}, Fixed{}, Fixed{}};
    const std::string message = expect_rejected(target_, encode(d));
    EXPECT_TRUE(contains(message, "unit quaternion")) << message;
    EXPECT_TRUE(names_one_of(message, {sphere.at, sphere.orientation_at})) << message;
  }
  // Just outside the tolerance (|q|^2 - 1 > 2^-20) is refused; the identity is fine.
  Decoded d = decoded_;
  d.bodies[1].orientation =
      Quat{Fixed::from_raw(Fixed::one_raw + (Fixed::one_raw >> 19)), Fixed{}, Fixed{}, Fixed{}};
  expect_rejected(target_, encode(d));
  d.bodies[1].orientation = Quat{};
  const Bytes good = encode(d);
  const Status st = target_.restore(good);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_EQ(target_.save(), good);
}

TEST_F(RejectedRestore, ContactsMustNameExistingBodiesInOrder) {
  const DecodedContact& last = decoded_.contacts.back();
  Decoded d = decoded_;
  d.contacts.back().b_minus_a = 0xFFFFFFF0U - last.a;  // b: no such body (and still ascending)
  std::string message = expect_rejected(target_, encode(d));
  EXPECT_TRUE(names_one_of(message, {last.at, last.b_at})) << message;

  // A body ID that was once issued, but not to a body in this state: a contact whose b becomes
  // that ID while the pairs stay ascending.
  World gap = source_;
  const BodyId removed = gap.body_ids()[4];
  ASSERT_TRUE(gap.destroy_body(removed).ok());
  const Decoded with_gap = decode(gap.save());
  ASSERT_TRUE(with_gap.ok) << with_gap.error;
  const std::vector<DecodedContact>& cs = with_gap.contacts;
  std::size_t pick = cs.size();
  for (std::size_t i = 0; i < cs.size() && pick == cs.size(); ++i) {
    const bool after_previous = i == 0 || cs[i - 1].a != cs[i].a || cs[i - 1].b < removed.value;
    const bool before_next =
        i + 1 == cs.size() || cs[i + 1].a != cs[i].a || cs[i + 1].b > removed.value;
    if (cs[i].a < removed.value && after_previous && before_next) pick = i;
  }
  ASSERT_LT(pick, cs.size());
  d = with_gap;
  d.contacts[pick].b_minus_a = removed.value - cs[pick].a;
  expect_rejected(target_, encode(d));

  d = decoded_;  // a == b
  d.contacts.back().b_minus_a = 0;
  message = expect_rejected(target_, encode(d));
  EXPECT_TRUE(names_one_of(message, {last.at, last.b_at})) << message;

  // Two pairs with the same a (a step 0) out of order: their b - a swapped.
  std::size_t same_a = 0;
  while (same_a + 1 < decoded_.contacts.size() && decoded_.contacts[same_a + 1].a_step != 0)
    ++same_a;
  ASSERT_LT(same_a + 1, decoded_.contacts.size()) << "no two contacts share their body a";
  d = decoded_;
  std::swap(d.contacts[same_a].b_minus_a, d.contacts[same_a + 1].b_minus_a);
  message = expect_rejected(target_, encode(d));
  EXPECT_TRUE(contains(message, "byte")) << message;

  // A duplicate pair: the first contact written twice (the copy with a step 0).
  d = decoded_;
  DecodedContact copy = d.contacts[0];
  copy.a_step = 0;
  d.contacts.insert(d.contacts.begin() + 1, copy);
  message = expect_rejected(target_, encode(d));
  const std::size_t copy_at = decoded_.contacts[1].at;
  EXPECT_TRUE(names_one_of(message, {copy_at, copy_at + 1})) << message;
}

TEST_F(RejectedRestore, ContactFlagsMustBeConsistent) {
  // The point byte: the count in bits 0-2 (0-4), reported in bit 3 (only with points), sub-shapes
  // follow in bit 4, nothing else. (Touching is "has points", so version 1's "points but not
  // touching" cannot be written.)
  const auto with_points = static_cast<std::size_t>(
      std::find_if(decoded_.contacts.begin(), decoded_.contacts.end(),
                   [](const DecodedContact& c) { return c.point_count() > 0; }) -
      decoded_.contacts.begin());
  ASSERT_LT(with_points, decoded_.contacts.size());
  const DecodedContact& c = decoded_.contacts[with_points];
  // Sub-shapes must be parts the shapes have: these pairs are of whole shapes (sub-shape 0 only),
  // and bit 4 with both 0 is not canonical.
  for (const auto& [sub_a, sub_b, part] :
       {std::tuple{1, 0, "sub-shape 1 of body"}, std::tuple{0, 3, "sub-shape 3 of body"},
        std::tuple{0, 0, "not both 0"}}) {
    Decoded d = decoded_;
    d.contacts[with_points].points_byte = static_cast<std::uint8_t>(c.points_byte | kSubShapes);
    d.contacts[with_points].sub_a = static_cast<std::uint64_t>(sub_a);
    d.contacts[with_points].sub_b = static_cast<std::uint64_t>(sub_b);
    const std::string message = expect_rejected(target_, encode(d));
    EXPECT_TRUE(contains(message, part)) << message;
  }
  for (const int bits : {0x20, 0x40, 0x80, 0xE0}) {  // bits that mean nothing
    Decoded d = decoded_;
    d.contacts[with_points].points_byte = static_cast<std::uint8_t>(c.points_byte | bits);
    const std::string message = expect_rejected(target_, encode(d));
    EXPECT_TRUE(names_one_of(message, {c.at, c.points_at})) << message;
  }
  // Five to seven points (the record written in full).
  for (std::uint8_t count = 5; count <= 7; ++count) {
    Decoded d = decoded_;
    DecodedContact& more = d.contacts[with_points];
    more.points_byte = static_cast<std::uint8_t>((more.points_byte & kReported) | count);
    while (more.points.size() < count)
      more.points.push_back(more.points.back());
    const std::string message = expect_rejected(target_, encode(d));
    EXPECT_TRUE(names_one_of(message, {c.at, c.points_at})) << message;
  }
  // The same contact without its points: valid with a point byte of 0, refused when reported.
  Decoded none = decoded_;
  none.contacts[with_points].points.clear();
  none.contacts[with_points].points_byte = 0;
  {
    World w;
    const Status st = w.restore(encode(none));
    EXPECT_TRUE(st.ok()) << "the edited record itself should be valid: " << st.message();
  }
  none.contacts[with_points].points_byte = kReported;
  const std::string message = expect_rejected(target_, encode(none));
  EXPECT_TRUE(names_one_of(message, {c.at, c.points_at})) << message;
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
  put_i64(bad, decoded_.def_at + kDtInDefinition, 0);  // dt = 0
  message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "dt")) << message;

  bad = state_;
  put_u32(bad, decoded_.def_at + kSubstepsInDefinition, 0);  // substeps = 0
  expect_rejected(target_, bad);

  bad = state_;
  bad[decoded_.def_at + kDefinitionBytes - 3 * 8 - 1] = 2;  // enable sleep: not a bool
  expect_rejected(target_, bad);

  // A static body (the ground) marked awake.
  ASSERT_EQ(decoded_.sets[0].type, BodyType::static_body);
  ASSERT_EQ(decoded_.bodies[0].flags, 0);
  Decoded d = decoded_;
  d.bodies[0].flags = kAwake;
  message = expect_rejected(target_, encode(d));
  EXPECT_TRUE(names_one_of(message, {decoded_.bodies[0].at, decoded_.bodies[0].flags_at}))
      << message;

  // A dynamic sphere with negative mass, and with a negative friction.
  const auto sphere_set = static_cast<std::size_t>(decoded_.bodies[1].set);
  ASSERT_EQ(decoded_.sets[sphere_set].type, BodyType::dynamic);
  d = decoded_;
  d.sets[sphere_set].mass = -1_fx;
  expect_rejected(target_, encode(d));
  d = decoded_;
  d.sets[sphere_set].friction = -Fixed::epsilon();
  expect_rejected(target_, encode(d));

  // What create_body refuses, restore refuses too (docs/SIM.md, "What is refused"): a mass at the
  // top of the range (saturated), a dynamic body whose mass or inertia has no inverse in range
  // (2 ulp: 1 / x = 2^31), and a velocity component beyond 2^30.
  d = decoded_;
  d.sets[sphere_set].mass = Fixed::max();
  message = expect_rejected(target_, encode(d));
  EXPECT_TRUE(contains(message, "mass")) << message;
  d = decoded_;
  d.sets[sphere_set].inertia.y = Fixed::from_raw(2);
  message = expect_rejected(target_, encode(d));
  EXPECT_TRUE(contains(message, "inertia")) << message;
  d = decoded_;
  d.bodies[1].linear_velocity.x = Fixed::from_int(1 << 30) + Fixed::epsilon();
  message = expect_rejected(target_, encode(d));
  EXPECT_TRUE(contains(message, "velocity")) << message;
  // Just inside each limit: accepted.
  d = decoded_;
  d.bodies[1].linear_velocity.x = Fixed::from_int(1 << 30);
  World w = make_world(WorldDef{});
  EXPECT_TRUE(w.restore(encode(d)).ok());
}

}  // namespace
}  // namespace detsim
